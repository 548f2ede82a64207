"""The package dem_mobility_tools as users get it: pip installs it (Debian's setuptools, offline,
into a temporary venv) with every console script of pyproject.toml, and each one answers --help
from the installed copy; catkin's catkin_python_setup() reads the package from setup.py with
package.xml's version, and python/bin holds a program for each console script (what
catkin_install_python() installs for rosrun). No module of the repository changes sys.path.

    PYTHONPATH=python python3 -m unittest test/python/test_package.py -v      (from the repository root)
"""
import os
import re
import shutil
import subprocess
import sys
import tempfile
import tomllib
import unittest
import xml.etree.ElementTree as ET

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
INTERROGATE = '/usr/share/catkin/cmake/interrogate_setup_dot_py.py'  # Debian's catkin


def console_scripts():
    with open(os.path.join(ROOT, 'pyproject.toml'), 'rb') as fh:
        return tomllib.load(fh)['project']['scripts']


def package_version():
    return ET.parse(os.path.join(ROOT, 'package.xml')).getroot().find('version').text.strip()


def sources(dest):
    """The files pip and catkin read (setup.py, pyproject.toml, package.xml, python/) copied to
    `dest`: a build in the checkout would write build/ and *.egg-info there."""
    os.makedirs(dest)
    for f in ('setup.py', 'pyproject.toml', 'package.xml'):
        shutil.copy(os.path.join(ROOT, f), dest)
    shutil.copytree(os.path.join(ROOT, 'python'), os.path.join(dest, 'python'),
                    ignore=shutil.ignore_patterns('__pycache__', '*.egg-info'))
    return dest


def clean_env(**more):
    """The environment without PYTHONPATH: what runs must come from the installed copy."""
    env = {k: v for k, v in os.environ.items() if k != 'PYTHONPATH'}
    env.update(more)
    return env


class Programs(unittest.TestCase):
    def test_python_bin_has_each_console_script_and_nothing_else(self):
        scripts = console_scripts()
        self.assertIn('dm-doe', scripts)
        self.assertEqual(scripts['dm-docs'], 'dem_mobility_tools.docsgen.make:main')
        self.assertEqual(sorted(os.listdir(os.path.join(ROOT, 'python', 'bin'))), sorted(scripts))
        for name, target in scripts.items():
            module, func = target.split(':')
            path = os.path.join(ROOT, 'python', 'bin', name)
            with open(path) as fh:
                text = fh.read()
            self.assertTrue(text.startswith('#!/usr/bin/env python3\n'), path)
            self.assertIn('from %s import %s\n' % (module, func), text, path)
            self.assertIn('sys.exit(%s())' % func, text, path)
            self.assertTrue(os.access(path, os.X_OK), path + ' is not executable')

    def test_cmake_installs_every_program_of_python_bin(self):
        with open(os.path.join(ROOT, 'cmake', 'ros.cmake')) as fh:
            cmake = fh.read()
        self.assertIn('catkin_python_setup()', cmake)
        block = re.search(r'catkin_install_python\(PROGRAMS(.*?)DESTINATION \$\{CATKIN_PACKAGE_BIN_DESTINATION\}\)',
                          cmake, re.S)
        self.assertIsNotNone(block, 'no catkin_install_python(PROGRAMS ... ) in cmake/ros.cmake')
        self.assertEqual(sorted(block.group(1).split()), sorted('python/bin/' + n for n in console_scripts()))

    def test_no_module_changes_sys_path(self):
        needle = 'sys.path.' + 'insert'  # (not spelt out: this file would find itself)
        found = []
        for folder in ('python', 'scripts', 'test', 'launch'):
            for d, _, files in os.walk(os.path.join(ROOT, folder)):
                for f in files:
                    path = os.path.join(d, f)
                    try:
                        with open(path, encoding='utf-8') as fh:
                            if needle in fh.read():
                                found.append(os.path.relpath(path, ROOT))
                    except (UnicodeDecodeError, OSError):
                        continue
        self.assertEqual(found, [])


class Catkin(unittest.TestCase):
    def test_catkin_python_setup_reads_the_package(self):
        self.assertTrue(os.path.isfile(INTERROGATE), 'no %s: install catkin (scripts/lib.sh DM_ROS_PACKAGES)'
                        % INTERROGATE)
        with tempfile.TemporaryDirectory() as tmp:
            out = os.path.join(tmp, 'setup_py.cmake')
            p = subprocess.run([sys.executable, INTERROGATE, 'dem_mobility', os.path.join(ROOT, 'setup.py'), out],
                               capture_output=True, text=True)
            self.assertEqual(p.returncode, 0, p.stderr)
            self.assertNotIn('not supported', p.stderr)  # (entry points: catkin's devel space ignores them)
            with open(out) as fh:
                got = dict(re.findall(r'set\(dem_mobility_SETUP_PY_(\w+) "(.*)"\)', fh.read()))
        self.assertEqual(got['VERSION'], package_version())
        self.assertEqual(got['PACKAGES'], 'dem_mobility_tools')
        self.assertEqual(got['PACKAGE_DIRS'], 'python/dem_mobility_tools')


class Installed(unittest.TestCase):
    """pip install --no-deps --no-build-isolation into a venv that sees Debian's packages (numpy,
    yaml, GDAL, rospy: python3 -m venv --system-site-packages), then each console script's --help."""

    @classmethod
    def setUpClass(cls):
        cls.tmp = tempfile.mkdtemp(prefix='dm_package_')
        cls.venv = os.path.join(cls.tmp, 'venv')
        p = subprocess.run([sys.executable, '-m', 'venv', '--system-site-packages', '--without-pip', cls.venv],
                           capture_output=True, text=True)
        if p.returncode != 0:
            raise AssertionError('python3 -m venv failed (Debian: python3-venv, scripts/lib.sh): ' + p.stderr)
        cls.python = os.path.join(cls.venv, 'bin', 'python')
        src = sources(os.path.join(cls.tmp, 'src'))
        # Debian's pip (python3-pip), seen through the system site packages, installs into the venv
        cls.pip = subprocess.run([cls.python, '-m', 'pip', 'install', '--no-deps', '--no-build-isolation',
                                  '--no-index', '--disable-pip-version-check', src],
                                 capture_output=True, text=True, env=clean_env(), cwd=cls.tmp)

    @classmethod
    def tearDownClass(cls):
        shutil.rmtree(cls.tmp, ignore_errors=True)

    def setUp(self):
        self.assertEqual(self.pip.returncode, 0, 'pip install failed (Debian: python3-pip, python3-setuptools):\n'
                         + self.pip.stdout[-3000:] + self.pip.stderr[-3000:])

    def test_the_package_imported_is_the_installed_copy(self):
        p = subprocess.run([self.python, '-c', 'import dem_mobility_tools.doe.cli as m; print(m.__file__)'],
                           capture_output=True, text=True, env=clean_env(), cwd=self.tmp)
        self.assertEqual(p.returncode, 0, p.stderr)
        self.assertTrue(p.stdout.strip().startswith(self.venv), p.stdout)

    def test_every_console_script_answers_help(self):
        for name in console_scripts():
            with self.subTest(name):
                exe = os.path.join(self.venv, 'bin', name)
                self.assertTrue(os.access(exe, os.X_OK), 'pip installed no %s' % exe)
                p = subprocess.run([exe, '--help'], capture_output=True, text=True, env=clean_env(), cwd=self.tmp,
                                   timeout=120)
                self.assertEqual(p.returncode, 0, '%s --help: %s' % (name, p.stdout[-2000:] + p.stderr[-2000:]))
                self.assertIn(name, p.stdout)
                self.assertNotIn('Traceback', p.stderr)


if __name__ == '__main__':
    unittest.main()
