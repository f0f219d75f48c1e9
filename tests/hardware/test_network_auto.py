"""`--interface auto`: the one NIC on the robot's network 192.168.123.0/24, or a refusal that says what to do."""

from __future__ import annotations

import ipaddress

import pytest

from g1_control.deploy.backends import check_link_endpoint
from g1_control.errors import NetworkInterfaceError
from g1_control.hardware.links import network
from g1_control.launch.schema import BackendConfig

A = ipaddress.IPv4Interface


def test_the_kernel_reports_loopbacks_address():
    assert network.interface_ipv4("lo") == A("127.0.0.1/8")
    assert network.interface_ipv4("nonexistent0") is None
    assert network.interface_table()["lo"] == A("127.0.0.1/8")


def test_the_one_nic_on_the_robot_network_is_chosen():
    table = {"lo": A("127.0.0.1/8"), "wlan0": A("10.1.2.3/24"), "enp3s0": A("192.168.123.99/24"), "docker0": None}
    assert network.robot_interface(table) == ("enp3s0", A("192.168.123.99/24"))


def test_none_or_two_nics_on_the_robot_network_are_refused_by_name():
    with pytest.raises(NetworkInterfaceError, match=r"no interface here has an address on the robot's network "
                       r"192\.168\.123\.0/24 \(interfaces: lo 127\.0\.0\.1/8, eth0 no IPv4\)"):
        network.robot_interface({"lo": A("127.0.0.1/8"), "eth0": None})
    with pytest.raises(NetworkInterfaceError, match=r"2 interfaces are on the robot's network 192\.168\.123\.0/24 "
                       r"\(eth0 192\.168\.123\.10/24, eth1 192\.168\.123\.11/24\); name the one cabled"):
        network.robot_interface({"eth0": A("192.168.123.10/24"), "eth1": A("192.168.123.11/24")})
    # on the subnet by prefix, not by the first three numbers of another network's address
    with pytest.raises(NetworkInterfaceError):
        network.robot_interface({"eth0": A("192.168.12.3/24")})


def test_check_link_endpoint_resolves_auto_in_the_config(monkeypatch):
    # loopback stands in for the robot's NIC here: it exists and is up on every machine
    monkeypatch.setattr(network, "interface_table", lambda: {"lo": A("192.168.123.99/24")})
    config = BackendConfig(type="unitree_dds", interface="auto")
    what = check_link_endpoint(config)
    assert config.interface == "lo"
    assert what.startswith("interface lo exists and is up (auto: the one NIC on 192.168.123.0/24, 192.168.123.99/24)")
