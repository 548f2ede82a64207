#!/usr/bin/env python3
"""Fails when a test log shows a skipped test that test/allowed_skips.yaml does not list.

    check_skips.py [--list FILE] LOG...    every skip in the logs against the list (default:
                                           test/allowed_skips.yaml beside this file)
    check_skips.py --self-test             skips planted in logs of each kind must be found

What counts as a skip, by the log's kind (a log may hold several kinds and several runs):
  - GoogleTest: "[  SKIPPED ] Suite.Test (N ms)" (its message: the lines since "[ RUN      ]"),
    a name in the summary's list of skipped tests, and "YOU HAVE N DISABLED TESTS";
  - ctest: a test "***Skipped" or "***Not Run", and the "(Skipped)"/"(Disabled)"/"(Not Run)"
    lines of its summary;
  - python unittest: "test (module.Class...) ... skipped 'reason'" (the verbose form), and the
    count of "OK (skipped=N)" / "FAILED (..., skipped=N)": skips it counts but does not name (a
    run without -v) are unlisted, since they cannot be matched;
  - catkin_test_results: a result file's "NAME: ..., N skipped" line, and the skips of its
    "Summary: ..., N skipped" that no such line names (unnamed: unlisted).
Every unlisted skip is named with its log; the exit status is then 1. A log that is missing or
empty is an error (exit 2): nothing was checked.
"""
import fnmatch
import io
import os
import re
import sys
import tempfile
from contextlib import redirect_stdout

import yaml

HERE = os.path.dirname(os.path.abspath(__file__))
DEFAULT_LIST = os.path.join(HERE, 'allowed_skips.yaml')

GTEST_RUN = re.compile(r'^\[ RUN      \] (\S+)')
GTEST_SKIPPED = re.compile(r'^\[  SKIPPED \] (\S+) \(\d+ ms\)')
GTEST_SKIPPED_LISTED = re.compile(r'^\[  SKIPPED \] (\S+)\s*$')  # the summary's list (no message)
GTEST_DISABLED = re.compile(r'YOU HAVE (\d+) DISABLED TESTS?')
CTEST_SKIPPED = re.compile(r'Test\s+#\d+: (\S+) \.*\s*\*+(Skipped|Not Run)')
CTEST_SUMMARY = re.compile(r'^\s*\d+ - (\S+) \((Skipped|Disabled|Not Run)\)')
UNITTEST_HEAD = re.compile(r'^(\w+) \(([\w.]+)\)')
UNITTEST_SKIPPED = re.compile(r"(?:^|\.\.\. )skipped '(.*)'\s*$")
UNITTEST_COUNT = re.compile(r'^(?:OK|FAILED) \((?:.*, )?skipped=(\d+)')
CATKIN_FILE = re.compile(r'^(\S+): \d+ tests?, \d+ errors?, \d+ failures?, (\d+) skipped')
CATKIN_SUMMARY = re.compile(r'Summary: \d+ tests?, \d+ errors?, \d+ failures?, (\d+) skipped')


class ListError(Exception):
    pass


def load_list(path):
    """The allowed skips: [{'test', 'message', 'reason'}], each checked (file and entry named)."""
    try:
        with open(path) as fh:
            doc = yaml.safe_load(fh)
    except (OSError, yaml.YAMLError) as e:
        raise ListError('%s: cannot read the list of allowed skips: %s' % (path, e))
    if doc is None:
        doc = []
    if not isinstance(doc, list):
        raise ListError('%s: the list of allowed skips must be a YAML list of entries' % path)
    for i, e in enumerate(doc):
        where = '%s: entry %d' % (path, i + 1)
        if not isinstance(e, dict):
            raise ListError('%s: must be a mapping with test, message and reason' % where)
        unknown = sorted(set(e) - {'test', 'message', 'reason'})
        if unknown:
            raise ListError('%s: unknown key %s (test, message, reason)' % (where, unknown[0]))
        for key in ('test', 'message', 'reason'):
            if not isinstance(e.get(key), str) or not e[key].strip():
                raise ListError('%s: %s must be a non-empty string' % (where, key))
        try:
            re.compile(e['message'])
        except re.error as err:
            raise ListError('%s: message is not a regular expression: %s' % (where, err))
    return doc


def skips_in(text):
    """The skips a log shows: [(name, message)]; name None for skips counted but not named."""
    found = []
    gtest_current, gtest_lines = None, []
    unittest_head, unittest_named = None, 0
    catkin_named = 0
    for line in text.splitlines():
        m = GTEST_RUN.match(line)
        if m:
            gtest_current, gtest_lines = m.group(1), []
            continue
        m = GTEST_SKIPPED.match(line)
        if m:
            msg = '\n'.join(l for l in gtest_lines if not l.endswith(': Skipped')).strip()
            found.append((m.group(1), msg if gtest_current == m.group(1) else ''))
            gtest_current = None
            continue
        m = GTEST_SKIPPED_LISTED.match(line)
        if m:
            found.append((m.group(1), ''))  # (one already found with its message is kept as that)
            continue
        if gtest_current is not None:
            gtest_lines.append(line)
        m = GTEST_DISABLED.search(line)
        if m:
            found.append((None, '%s disabled GoogleTest test(s)' % m.group(1)))
            continue
        m = CTEST_SKIPPED.search(line) or CTEST_SUMMARY.match(line)
        if m:
            found.append(('ctest:' + m.group(1), 'ctest: ' + m.group(2)))
            continue
        m = CATKIN_FILE.match(line)
        if m and not line.startswith('Summary:'):
            if int(m.group(2)) > 0:
                found.append(('catkin:' + m.group(1), '%s skipped in this result file' % m.group(2)))
                catkin_named += int(m.group(2))
            continue
        m = CATKIN_SUMMARY.search(line)
        if m:
            unnamed = int(m.group(1)) - catkin_named
            if unnamed > 0:
                found.append((None, '%d skipped catkin test(s) not named' % unnamed))
            catkin_named = 0
            continue
        m = UNITTEST_HEAD.match(line)
        if m:
            method, where = m.groups()
            unittest_head = where if where.endswith('.' + method) else where + '.' + method
        m = UNITTEST_SKIPPED.search(line)
        if m:
            found.append((unittest_head or '(unittest, unnamed)', m.group(1)))
            unittest_named += 1
            continue
        m = UNITTEST_COUNT.match(line)
        if m:
            unnamed = int(m.group(1)) - unittest_named
            if unnamed > 0:
                found.append((None, '%d skipped unittest test(s) not named (run unittest with -v)' % unnamed))
            unittest_head, unittest_named = None, 0
    # a name that shows twice (GoogleTest's summary) is one skip
    seen, out = set(), []
    for name, msg in found:
        if name is not None and name in seen:
            continue
        seen.add(name)
        out.append((name, msg))
    return out


def allowed(name, message, entries):
    for e in entries:
        if name is not None and fnmatch.fnmatchcase(name, e['test']) and re.search(e['message'], message or ''):
            return e
    return None


def check(logs, list_path):
    """0: every skip listed; 1: an unlisted skip (each named); 2: a bad list or log."""
    try:
        entries = load_list(list_path)
    except ListError as e:
        print('check_skips: %s' % e)
        return 2
    unlisted, listed = [], []
    for log in logs:
        try:
            with open(log, errors='replace') as fh:
                text = fh.read()
        except OSError as e:
            print('check_skips: %s: cannot read the log: %s' % (log, e.strerror))
            return 2
        if not text.strip():
            print('check_skips: %s: the log is empty (no test output to check)' % log)
            return 2
        for name, msg in skips_in(text):
            e = allowed(name, msg, entries)
            (listed if e else unlisted).append((log, name, msg, e))
    for log, name, msg, e in listed:
        print('check_skips: allowed: %s (%s)' % (name, ' '.join(e['reason'].split())))
    for log, name, msg, _ in unlisted:
        print('check_skips: NOT ALLOWED: %s: %s: %s' % (log, name or '(unnamed)', (msg or 'no message').splitlines()[0] if msg else 'no message'))
    if unlisted:
        print('check_skips: %d skipped test(s) not in %s (list a skip there only with its reason, '
              'e.g. an instruction set the CPU lacks)' % (len(unlisted), list_path))
        return 1
    print('check_skips: %d log(s), %d skip(s), all in %s' % (len(logs), len(listed), os.path.basename(list_path)))
    return 0


def self_test():
    """Planted skips of every kind must each be named as unlisted; the allowed ones must pass."""
    gtest = ('[ RUN      ] PairKernel/VectorInstance.Sweep/avx512\n'
             'pair_kernel_test.cpp:40: Skipped\npair kernel vector-avx512: this CPU lacks AVX-512 (F, VL, DQ, BW)\n\n'
             '[  SKIPPED ] PairKernel/VectorInstance.Sweep/avx512 (0 ms)\n'
             '[ RUN      ] Planted.GTestSkip\nplanted.cpp:1: Skipped\nno reason\n\n'
             '[  SKIPPED ] Planted.GTestSkip (0 ms)\n'
             '[ RUN      ] PairKernel/VectorInstance.Ledger/avx2\nx.cpp:1: Skipped\nthe soil was too wet\n\n'
             '[  SKIPPED ] PairKernel/VectorInstance.Ledger/avx2 (0 ms)\n'
             '[  SKIPPED ] 3 tests, listed below:\n[  SKIPPED ] PairKernel/VectorInstance.Sweep/avx512\n'
             '[  SKIPPED ] Planted.GTestSkip\n[  SKIPPED ] PairKernel/VectorInstance.Ledger/avx2\n')
    cases = [
        # (log text, the names that must be reported as unlisted (None: unnamed), exit status)
        (gtest, {'Planted.GTestSkip', 'PairKernel/VectorInstance.Ledger/avx2'}, 1),
        ('[ RUN      ] PairKernel/VectorInstance.Sweep/avx2\nx.cpp:3: Skipped\n'
         'pair kernel vector-avx2: this CPU lacks AVX2, FMA or BMI2\n\n'
         '[  SKIPPED ] PairKernel/VectorInstance.Sweep/avx2 (0 ms)\n[  PASSED  ] 4 tests.\n', set(), 0),
        ('  YOU HAVE 1 DISABLED TEST\n', {None}, 1),
        # only the summary's list (a brief run): no message, so not the listed skip
        ('[  SKIPPED ] 1 test, listed below:\n[  SKIPPED ] PairKernel/VectorInstance.Sweep/avx512\n',
         {'PairKernel/VectorInstance.Sweep/avx512'}, 1),
        ('12/30 Test #12: core.planted ....................***Skipped   0.01 sec\n', {'ctest:core.planted'}, 1),
        ('The following tests did not run:\n\t 14 - core.other (Disabled)\n', {'ctest:core.other'}, 1),
        ('3/9 Test #3: core.gone ........................***Not Run   0.00 sec\n', {'ctest:core.gone'}, 1),
        ("test_run (test_doe_run.Slurm.test_run) ... skipped 'no Slurm'\ntest_ok (test_x.A.test_ok) ... ok\n\n"
         "OK (skipped=1)\n", {'test_doe_run.Slurm.test_run'}, 1),
        ("test_run (test_doe_run.Slurm) ... printed by the test\nskipped 'no Slurm'\n"
         "FAILED (failures=1, skipped=1)\n", {'test_doe_run.Slurm.test_run'}, 1),
        ('..s.\n------\nRan 4 tests in 0.1s\n\nOK (skipped=1)\n', {None}, 1),
        ('Summary: 12 tests, 0 errors, 0 failures, 2 skipped\n', {None}, 1),
        ('rostest-test_road_scene.xml: 3 tests, 0 errors, 0 failures, 1 skipped\n'
         'Summary: 12 tests, 0 errors, 0 failures, 1 skipped\n', {'catkin:rostest-test_road_scene.xml'}, 1),
        ('Summary: 12 tests, 0 errors, 0 failures, 0 skipped\nOK\n', set(), 0),
    ]
    failures = []
    with tempfile.TemporaryDirectory(prefix='check_skips_') as tmp:
        for k, (text, want, status) in enumerate(cases):
            log = os.path.join(tmp, 'case%d.log' % k)
            with open(log, 'w') as fh:
                fh.write(text)
            out = io.StringIO()
            with redirect_stdout(out):
                got = check([log], DEFAULT_LIST)
            named = set()
            for line in out.getvalue().splitlines():
                if 'NOT ALLOWED' in line:
                    name = line.split(': ')[3]
                    named.add(None if name == '(unnamed)' else name)
            if got != status or named != want:
                failures.append('case %d: exit %d (want %d), unlisted %s (want %s)' % (k, got, status, sorted(map(str, named)), sorted(map(str, want))))
        # a missing log, an empty log and a bad list are errors, not passes
        empty = os.path.join(tmp, 'empty.log')
        open(empty, 'w').close()
        bad_list = os.path.join(tmp, 'bad.yaml')
        with open(bad_list, 'w') as fh:
            fh.write('- test: X.*\n  message: lacks\n  resaon: typo\n')
        for what, logs, lst, key in (('missing log', [os.path.join(tmp, 'none.log')], DEFAULT_LIST, 'none.log'),
                                     ('empty log', [empty], DEFAULT_LIST, 'empty.log'),
                                     ('bad list', [os.path.join(tmp, 'case1.log')], bad_list, 'resaon')):
            out = io.StringIO()
            with redirect_stdout(out):
                got = check(logs, lst)
            if got != 2 or key not in out.getvalue():
                failures.append('%s: exit %d (want 2), message naming %s: %r' % (what, got, key, out.getvalue()))
    for f in failures:
        print('check_skips self-test: FAILED %s' % f)
    if failures:
        return 1
    print('check_skips self-test: %d planted logs and 3 bad inputs, each judged as it must be' % len(cases))
    return 0


def main(argv):
    if argv[:1] == ['--self-test']:
        return self_test()
    list_path = DEFAULT_LIST
    if argv[:1] == ['--list']:
        if len(argv) < 2:
            print('usage: check_skips.py [--list FILE] LOG... | --self-test')
            return 2
        list_path, argv = argv[1], argv[2:]
    if not argv or argv[0].startswith('-'):
        print('usage: check_skips.py [--list FILE] LOG... | --self-test')
        return 2
    return check(argv, list_path)


if __name__ == '__main__':
    sys.exit(main(sys.argv[1:]))
