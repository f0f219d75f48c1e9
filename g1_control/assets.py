"""Models and data that come from registry packages, fetched the way a user can.

One small mechanism serves policies and demo data alike: `pip download` one pinned wheel
without its dependencies, check its SHA-256, extract only the files we need into a user cache
(`$G1_CONTROL_CACHE`, default `~/.cache/g1-control`). Nothing else is downloaded at run time.
"""

from __future__ import annotations

import fnmatch
import hashlib
import os
import subprocess
import sys
import tempfile
import zipfile
from dataclasses import dataclass
from pathlib import Path

from g1_control.errors import PolicyFetchError


@dataclass(frozen=True)
class WheelAsset:
    """Files taken from one pinned wheel of a registry package."""

    name: str
    package: str
    version: str
    sha256: str
    patterns: tuple[str, ...]
    license: str
    description: str

    @property
    def wheel_name(self) -> str:
        return f"{self.package.replace('-', '_')}-{self.version}-py3-none-any.whl"


ASSETS: dict[str, WheelAsset] = {
    "holosoma-policies": WheelAsset(
        name="holosoma-policies",
        package="holosoma-inference",
        version="0.1.3",
        sha256="3c11fd4595bc82921d4c44f77357667828761548c1ce74782ea77937b2ab0ef7",
        patterns=("holosoma_inference/models/loco/g1_29dof/*.onnx", "holosoma_inference/models/wbt/*g1_29dof*.onnx"),
        license="Apache-2.0 (as stated upstream by Amazon FAR; the wheel carries no license file)",
        description="pretrained G1 locomotion (ppo, fastsac) and whole-body-tracking policies (ONNX)",
    ),
    "holosoma-demo-mocap": WheelAsset(
        name="holosoma-demo-mocap",
        package="holosoma-retargeting",
        version="0.1.0",
        sha256="3dcdcc06c6705c091478808024298dfcc684d9eb49e890cc6b11fc03fa246cb4",
        patterns=("holosoma_retargeting/demo_data/*", "holosoma_retargeting/models/largebox/largebox.obj"),
        license="Apache-2.0 (as stated upstream by Amazon FAR)",
        description="demo human mocap: five box-climbing and two OMOMO box-lifting sequences (+ the box's mesh)",
    ),
}


def cache_dir() -> Path:
    return Path(os.environ.get("G1_CONTROL_CACHE") or Path.home() / ".cache" / "g1-control")


def asset_dir(name: str) -> Path:
    return cache_dir() / name / ASSETS[name].version


def _marker(asset: WheelAsset) -> str:
    """What `.complete` says once an asset is extracted: the wheel and the files taken from it, so a
    cache extracted for a shorter file list is extracted again."""
    return f"{asset.package}=={asset.version} sha256={asset.sha256} files={' '.join(asset.patterns)}\n"


def is_fetched(name: str) -> bool:
    marker = asset_dir(name) / ".complete"
    return marker.is_file() and marker.read_text() == _marker(ASSETS[name])


def _sha256(path: Path) -> str:
    digest = hashlib.sha256()
    with path.open("rb") as fh:
        for block in iter(lambda: fh.read(1 << 20), b""):
            digest.update(block)
    return digest.hexdigest()


def extract(asset: WheelAsset, wheel: Path, dest: Path) -> list[Path]:
    """Check `wheel` against the pinned hash and extract the asset's files into `dest`."""
    actual = _sha256(wheel)
    if actual != asset.sha256:
        raise PolicyFetchError(
            f"{wheel.name}: SHA-256 {actual} does not match the pinned {asset.sha256}; "
            "refusing to use it (a different or corrupted file)"
        )
    written = []
    with zipfile.ZipFile(wheel) as zf:
        for member in zf.namelist():
            if member.endswith("/") or not any(fnmatch.fnmatch(member, p) for p in asset.patterns):
                continue
            target = dest / member
            target.parent.mkdir(parents=True, exist_ok=True)
            target.write_bytes(zf.read(member))
            written.append(target)
    if not written:
        raise PolicyFetchError(f"{wheel.name} contains no file matching {asset.patterns}")
    (dest / ".complete").write_text(_marker(asset))
    return written


def pip_command() -> list[str] | None:
    """How to run pip here: this interpreter's own pip; else a pip on PATH (any pip downloads a
    pure-Python wheel); else uv's `uvx pip`; None when there is none (a uv venv on a machine without pip)."""
    import importlib.util
    import shutil

    if importlib.util.find_spec("pip") is not None:
        return [sys.executable, "-m", "pip"]
    for name in ("pip3", "pip"):
        found = shutil.which(name)
        if found:
            return [found]
    uv = shutil.which("uv")
    return [uv, "tool", "run", "pip"] if uv else None


def fetch(name: str, *, force: bool = False, quiet: bool = False, wheel: Path | None = None) -> Path:
    """Folder holding the asset's files, downloading the pinned wheel on first use.

    `wheel` uses a wheel file already on disk instead of the registry (offline machines).
    """
    if name not in ASSETS:
        raise PolicyFetchError(f"unknown asset '{name}'; known: {', '.join(sorted(ASSETS))}")
    asset, dest = ASSETS[name], asset_dir(name)
    if is_fetched(name) and not force:
        return dest
    dest.mkdir(parents=True, exist_ok=True)
    if wheel is not None:
        extract(asset, Path(wheel), dest)
        return dest
    with tempfile.TemporaryDirectory(prefix="g1-fetch-") as tmp:
        pip = pip_command()
        if pip is None:
            raise PolicyFetchError(
                f"this Python environment has no pip to download {asset.package}=={asset.version} with (uv makes "
                f"virtual environments without it). Either add pip (`uv pip install pip`, or `python -m ensurepip`) "
                f"and run again, or download the wheel with any pip or uv (`pip download --no-deps "
                f"{asset.package}=={asset.version} -d DIR`, or `uvx pip download ...`) and run "
                f"`g1 policies fetch --asset {asset.name} --wheel DIR/{asset.wheel_name}`"
            )
        if not quiet:
            print(f"Fetching {asset.package}=={asset.version} ({asset.description}) from the package registry ...",
                  file=sys.stderr)
        cmd = [*pip, "download", "--no-deps", "--only-binary=:all:", "--disable-pip-version-check", "-d", tmp,
               f"{asset.package}=={asset.version}"] + (["-q"] if quiet else [])
        proc = subprocess.run(cmd, capture_output=quiet, text=True, check=False)
        found = list(Path(tmp).glob("*.whl"))
        if proc.returncode != 0 or not found:
            detail = (proc.stderr or "").strip().splitlines()[-1:] if quiet else []
            raise PolicyFetchError(
                f"could not download {asset.package}=={asset.version} from the package registry "
                f"({' '.join(pip)} exit {proc.returncode}{': ' + detail[0] if detail else ''}). Check the network "
                f"or pip's index settings, or pass a wheel you already have with --wheel FILE"
            )
        extract(asset, found[0], dest)
    return dest
