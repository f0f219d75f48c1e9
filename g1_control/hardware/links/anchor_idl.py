"""The IDL type of the DDS links' keyless-instance anchor (dds.py: _anchor_keyless_instance): keyless, one
octet, written once per domain and kept. Importing this module needs cyclonedds."""

# No `from __future__ import annotations`: Cyclone resolves these annotations at run time.

from dataclasses import dataclass

from cyclonedds.idl import IdlStruct
from cyclonedds.idl.annotations import final
from cyclonedds.idl.types import uint8


@dataclass
@final
class InstanceAnchor_(IdlStruct, typename="g1_control.dds_.InstanceAnchor_"):
    value: uint8
