"""Build step: put copies of the launch files and the docs into the wheel (g1_control/_shipped/).

Everything else is in pyproject.toml. The repository keeps one copy of each file (launch/*.yaml,
README.md, docs/*.md, LICENSE, THIRD_PARTY_LICENSES.md); g1_control/resources.py finds them in
the checkout or, once installed from a wheel, under g1_control/_shipped/.
"""

import shutil
from pathlib import Path

from setuptools import setup
from setuptools.command.build_py import build_py

ROOT = Path(__file__).resolve().parent
SHIPPED = {
    "launch": ["launch/*.yaml"],
    "docs": ["README.md", "LICENSE", "THIRD_PARTY_LICENSES.md", "docs/*.md"],
}


class BuildPyWithShippedFiles(build_py):
    def run(self):
        super().run()
        if getattr(self, "editable_mode", False):
            return  # an editable install reads the checkout's own files
        for folder, patterns in SHIPPED.items():
            dest = Path(self.build_lib) / "g1_control" / "_shipped" / folder
            dest.mkdir(parents=True, exist_ok=True)
            for pattern in patterns:
                for src in sorted(ROOT.glob(pattern)):
                    shutil.copyfile(src, dest / src.name)


setup(cmdclass={"build_py": BuildPyWithShippedFiles})
