"""Maps the top-level folders sim/, hardware/ and policies/ under the g1_control namespace.

Everything else about the package lives in pyproject.toml.
"""

from setuptools import find_packages, setup

MAPPED_FOLDERS = {"sim": "g1_control.sim", "hardware": "g1_control.hardware", "policies": "g1_control.policies"}

packages = find_packages(include=["g1_control", "g1_control.*"])
package_dir = {"g1_control": "g1_control"}
for folder, package in MAPPED_FOLDERS.items():
    package_dir[package] = folder
    packages += [package] + [f"{package}.{sub}" for sub in find_packages(folder)]

setup(
    packages=packages,
    package_dir=package_dir,
    package_data={"g1_control.policies": ["*.json", "*.yaml", "*.onnx", "*.pt"], "g1_control": ["py.typed"]},
)
