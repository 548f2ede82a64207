"""The package dem_mobility_tools (python/) for catkin_python_setup() and for pip (pyproject.toml
holds the console scripts; catkin does not take entry points, it installs python/bin instead)."""
from catkin_pkg.python_setup import generate_distutils_setup
from setuptools import find_packages, setup

setup(**generate_distutils_setup(packages=find_packages('python'), package_dir={'': 'python'}))
