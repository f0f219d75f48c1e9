"""Unitree's official G1 message definitions (PyPI unitree_sdk2 1.0.1), loaded as a test oracle.

The wheel's top-level __init__ imports a `b2` subpackage it does not ship, so the package object
is put in place by hand (with the real path) and only its IDL and CRC-packing modules are
imported. Its native CRC library is missing too; the CRC oracle runs the wheel's own packing with
a bit-by-bit CRC written here from the algorithm's definition.
Install: pip install --no-deps unitree_sdk2==1.0.1 (and cyclonedds, scripts/install_cyclonedds.sh).
"""

from __future__ import annotations

import ctypes
import importlib.util
import sys
import types

_spec = importlib.util.find_spec("unitree_sdk2py")
if _spec is None or not _spec.submodule_search_locations:
    raise ImportError(
        "the reference package unitree_sdk2 is not installed; run "
        "`pip install --no-deps unitree_sdk2==1.0.1` (see scripts/install_unitree_reference.sh)"
    )
if "unitree_sdk2py" not in sys.modules:
    _pkg = types.ModuleType("unitree_sdk2py")
    _pkg.__path__ = list(_spec.submodule_search_locations)
    sys.modules["unitree_sdk2py"] = _pkg

from unitree_sdk2py.idl.unitree_api.msg import dds_ as api  # noqa: E402  (after the package stub above)
from unitree_sdk2py.idl.unitree_hg.msg import dds_ as hg  # noqa: E402

from g1_control.hardware.unitree.crc import crc32_words_bitwise  # noqa: E402

__all__ = ["api", "crc32_bitwise", "hg", "official_crc"]

crc32_bitwise = crc32_words_bitwise  # the CRC as its definition reads (g1_control/hardware/unitree/crc.py)


class _ReferenceCrcLib:
    """Stands in for the wheel's missing crc_amd64.so."""

    def __init__(self, _path):
        def crc32_core(array, length):
            return crc32_bitwise(array[i] for i in range(length))

        self.crc32_core = crc32_core


def official_crc(msg) -> int:
    """The CRC Unitree's SDK computes for an official LowCmd_/LowState_ sample."""
    from unitree_sdk2py.utils import crc as crc_module

    real = ctypes.CDLL
    ctypes.CDLL = _ReferenceCrcLib
    try:
        calculator = crc_module.CRC()
        calculator.__init__()  # Singleton: make sure the stand-in library is the one in use
    finally:
        ctypes.CDLL = real
    return calculator.Crc(msg)
