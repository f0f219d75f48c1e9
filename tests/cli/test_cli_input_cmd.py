"""`g1 input`: the live check of a device, run through the real CLI entry point."""

import os

from g1_control.cli.main import main
from g1_control.teleop import evdev_protocol as ev
from g1_control.teleop.gamepad import EvdevGamepad


def test_g1_input_shows_commands_and_actions(tmp_path, capsys):
    fifo = tmp_path / "event0"
    os.mkfifo(fifo)
    keep = os.open(fifo, os.O_RDWR)  # a writer is connected before the device opens the pipe
    mapping = tmp_path / "pad.yaml"
    mapping.write_text("buttons: {Y: estop}\nslew_rate: {vx: null}\naxes: {speed_scale: null}\n")
    os.write(keep, ev.pack_event(ev.EV_ABS, ev.ABS_Y, -32768) + ev.pack_event(ev.EV_KEY, ev.BTN_WEST, 1)
             + ev.syn_report())
    try:
        rc = main(["input", "gamepad", "--path", str(fifo), "--mapping", str(mapping), "--seconds", "0.1",
                   "--rate", "100"])
    finally:
        os.close(keep)
    out = capsys.readouterr().out
    assert rc == 0
    assert "[estop]" in out and "vx +1.00 m/s" in out and "1 actions" in out


def test_g1_input_reports_loss(tmp_path, capsys, monkeypatch):
    fifo = tmp_path / "event0"
    os.mkfifo(fifo)
    keep = os.open(fifo, os.O_RDWR)
    original = EvdevGamepad._open

    def open_then_unplug(self, path, where):
        # the writer goes away right after the device opened: the first poll finds end of stream
        fd = original(self, path, where)
        os.close(keep)
        return fd

    monkeypatch.setattr(EvdevGamepad, "_open", open_then_unplug)
    assert main(["input", "gamepad", "--path", str(fifo), "--seconds", "5"]) == 1
    assert "device lost:" in capsys.readouterr().out


def test_g1_input_bad_mapping_file(tmp_path, capsys):
    fifo = tmp_path / "event0"
    os.mkfifo(fifo)
    bad = tmp_path / "bad.yaml"
    bad.write_text("buttons: {Q: run}\n")
    assert main(["input", "gamepad", "--path", str(fifo), "--mapping", str(bad)]) == 1
    assert "input.mapping.buttons.Q: 'Q' is not a button of a gamepad" in capsys.readouterr().err
