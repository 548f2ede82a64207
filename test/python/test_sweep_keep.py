"""Unit tests of dem_mobility_tools.sweep.keep (no ROS, no C++ build): a long sweep's finished runs
kept in git as they end, and a sweep on another machine resuming from them. The runs are
test_dm_sweep's stand-in command.

    PYTHONPATH=python python3 -m unittest discover -s test/python -p test_sweep_keep.py
"""
import os
import unittest

import yaml

from test_dm_sweep import Base
from dem_mobility_tools import sweep as dm_sweep


class KeepInGit(Base):
    """dm_sweep.keep: each good run's result, compacted, committed on its own as it ends; a sweep
    started again from a fresh clone of that repository (no runs folder) takes them as done and
    runs only the rest."""

    def git(self, repo, *argv):
        import subprocess
        return subprocess.run(['git', '-C', repo] + list(argv), check=True, capture_output=True, text=True).stdout

    def test_runs_kept_as_they_end_and_a_fresh_clone_resumes_from_them(self):
        from dem_mobility_tools.sweep import keep as dm_keep
        repo = os.path.join(self.tmp, 'repo')
        os.makedirs(repo)
        self.git(repo, 'init', '-q')
        self.git(repo, 'config', 'user.email', 't@example.org')
        self.git(repo, 'config', 'user.name', 'test')
        with open(os.path.join(repo, 'staged.txt'), 'w') as fh:
            fh.write('not part of any run\n')
        self.git(repo, 'add', 'staged.txt')
        self.git(repo, 'commit', '-q', '-m', 'start')
        with open(os.path.join(repo, 'staged.txt'), 'a') as fh:
            fh.write('staged, uncommitted\n')
        self.git(repo, 'add', 'staged.txt')
        keep_dir = os.path.join(repo, 'kept')
        cases = dm_sweep.cases([{'mode': 'ok', 'x': 1}, {'mode': 'fail', 'x': 2}, {'mode': 'ok', 'x': 3}])
        log = []

        def on_done(o):
            if o.ok:
                log.append(dm_keep.keep_run(o.result_file, keep_dir, o.name, commit=True, root=repo,
                                            message='run %s' % o.name, extra={'kept_from_commit': 'abc'}))
        first = self.sweep(cases, on_done=on_done)
        first.run()
        self.assertEqual(sorted(p for p, why in log if why is None),
                         [os.path.join(keep_dir, 'modeok_x1.yaml'), os.path.join(keep_dir, 'modeok_x3.yaml')])
        # one commit per good run, each holding its file alone; the staged change is still staged
        subjects = self.git(repo, 'log', '--format=%s').split('\n')
        self.assertEqual(sorted(subjects[:2]), ['run modeok_x1', 'run modeok_x3'])
        self.assertEqual(self.git(repo, 'show', '--name-only', '--format=', 'HEAD').split(),
                         ['kept/' + subjects[0].split()[1] + '.yaml'])
        self.assertIn('staged.txt', self.git(repo, 'diff', '--cached', '--name-only'))
        with open(os.path.join(keep_dir, 'modeok_x1.yaml')) as fh:
            kept = yaml.safe_load(fh)
        self.assertEqual(kept['kept_from_commit'], 'abc')
        self.assertEqual(kept['value'], 2.0)
        # a fresh clone elsewhere: its runs folder is empty; the two kept runs are restored and kept,
        # the failed one runs again
        clone = os.path.join(self.tmp, 'clone')
        self.git(self.tmp, 'clone', '-q', repo, clone)
        os.remove(self.journal)
        self.runs = os.path.join(self.tmp, 'runs_on_the_new_machine')
        second = self.sweep(cases)
        restored = dm_keep.restore_kept(os.path.join(clone, 'kept'), self.runs, [c.name for c in cases],
                                        second.outcome_file)
        self.assertEqual(sorted(restored), ['modeok_x1', 'modeok_x3'])
        self.assertEqual(sorted(o.name for o in second.resume()), ['modeok_x1', 'modeok_x3'])
        second.run()
        self.assertEqual(self.starts(), ['modefail_x2'])

    def test_histories_decimated_to_at_most_200_rows_keeping_the_ends(self):
        from dem_mobility_tools.sweep import keep as dm_keep
        for n in (5, 200, 201, 1000, 1001):
            doc = {'value': 1.0, 'history': {'t': [0.01 * k for k in range(n)], 'x': list(range(n))},
                   'window': [0.8, 0.9]}
            small = dm_keep.compact(doc)
            rows = len(small['history']['t'])
            self.assertLessEqual(rows, 200, n)
            self.assertEqual(small['history']['x'][0], 0)
            self.assertEqual(small['history']['x'][-1], n - 1)
            self.assertEqual(small['history']['t'], [0.01 * x for x in small['history']['x']])  # rows kept whole
            self.assertEqual(small['window'], [0.8, 0.9])
            self.assertEqual(small.get('history_decimated_from'), n if n > 200 else None)
            if n > 200:
                self.assertGreater(rows, 100)


if __name__ == '__main__':
    unittest.main()
