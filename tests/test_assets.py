import hashlib
import zipfile

import pytest

from g1_control import assets
from g1_control.errors import PolicyFetchError


def make_wheel(tmp_path):
    wheel = tmp_path / "demo_pkg-1.0-py3-none-any.whl"
    with zipfile.ZipFile(wheel, "w") as zf:
        zf.writestr("demo_pkg/models/a.onnx", b"model-a")
        zf.writestr("demo_pkg/models/b.onnx", b"model-b")
        zf.writestr("demo_pkg/__init__.py", b"")
    return wheel, hashlib.sha256(wheel.read_bytes()).hexdigest()


def asset(sha):
    return assets.WheelAsset("demo", "demo-pkg", "1.0", sha, ("demo_pkg/models/*.onnx",), "MIT", "demo models")


def test_extracts_only_matching_files(tmp_path):
    wheel, sha = make_wheel(tmp_path)
    written = assets.extract(asset(sha), wheel, tmp_path / "out")
    assert sorted(p.name for p in written) == ["a.onnx", "b.onnx"]
    assert not (tmp_path / "out" / "demo_pkg" / "__init__.py").exists()
    assert (tmp_path / "out" / ".complete").is_file()


def test_hash_mismatch_is_refused(tmp_path):
    wheel, _ = make_wheel(tmp_path)
    with pytest.raises(PolicyFetchError, match="does not match the pinned"):
        assets.extract(asset("0" * 64), wheel, tmp_path / "out")
    assert not (tmp_path / "out" / ".complete").exists()


def test_unreachable_registry_gives_a_clear_error(tmp_path, monkeypatch):
    monkeypatch.setenv("G1_CONTROL_CACHE", str(tmp_path / "cache"))
    # pip with no index and an empty link folder: as if the registry could not be reached.
    monkeypatch.setenv("PIP_CONFIG_FILE", "/dev/null")
    monkeypatch.setenv("PIP_NO_INDEX", "1")
    monkeypatch.setenv("PIP_FIND_LINKS", str(tmp_path))
    with pytest.raises(PolicyFetchError, match="could not download holosoma-inference==0.1.3 from the package registry"):
        assets.fetch("holosoma-policies", quiet=True)
    assert not assets.is_fetched("holosoma-policies")


def test_unknown_asset():
    with pytest.raises(PolicyFetchError, match="unknown asset 'x'"):
        assets.fetch("x")


def test_empty_cache_variable_means_the_default(monkeypatch):
    monkeypatch.setenv("G1_CONTROL_CACHE", "")
    assert assets.cache_dir().is_absolute()


def test_without_pip_says_what_to_do(tmp_path, monkeypatch):
    """A uv-made venv has no pip: the error names the fixes instead of blaming the network."""
    import importlib.util
    import shutil

    real_find_spec = importlib.util.find_spec
    monkeypatch.setattr(importlib.util, "find_spec", lambda name, *a: None if name == "pip" else real_find_spec(name, *a))
    monkeypatch.setattr(shutil, "which", lambda name: None)
    monkeypatch.setenv("G1_CONTROL_CACHE", str(tmp_path))
    assert assets.pip_command() is None
    with pytest.raises(PolicyFetchError) as exc:
        assets.fetch("holosoma-policies", quiet=True)
    message = str(exc.value)
    assert "no pip" in message and "uv pip install pip" in message and "--wheel" in message
    assert "network" not in message


def test_pip_fallbacks(monkeypatch):
    import importlib.util
    import shutil

    real_find_spec = importlib.util.find_spec
    monkeypatch.setattr(importlib.util, "find_spec", lambda name, *a: None if name == "pip" else real_find_spec(name, *a))
    monkeypatch.setattr(shutil, "which", lambda name: {"uv": "/opt/uv"}.get(name))
    assert assets.pip_command() == ["/opt/uv", "tool", "run", "pip"]
    monkeypatch.setattr(shutil, "which", lambda name: {"pip3": "/usr/bin/pip3", "uv": "/opt/uv"}.get(name))
    assert assets.pip_command() == ["/usr/bin/pip3"]
