"""The package layout (everything else is in pyproject.toml): the repository's top-level folders install under
the one name `lagbench`, so site-packages gets `lagbench/` and nothing else. `lagbench/` holds the command line
and the ground floor (files/); each folder in FOLDERS becomes `lagbench.<folder>` with all its subpackages."""
from setuptools import find_packages, setup

FOLDERS = ("systems", "models", "replication", "reports", "speedstudy")

package_dir = {"lagbench": "lagbench", **{f"lagbench.{f}": f for f in FOLDERS}}
packages = ["lagbench", *(f"lagbench.{p}" for p in find_packages("lagbench"))]
for folder in FOLDERS:
    packages += [f"lagbench.{folder}", *(f"lagbench.{folder}.{p}" for p in find_packages(folder))]

setup(package_dir=package_dir, packages=packages)
