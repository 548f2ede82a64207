"""scripts/pinned.sh refuses what it cannot run before it builds anything: no command, a name that
is no commit (named), no `--` before the command. (Its build and run are what the long sweeps use;
docs/sweeps.md.)"""
import os
import subprocess
import tempfile
import unittest

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
SCRIPT = os.path.join(ROOT, 'scripts', 'pinned.sh')


class PinnedScriptRefusals(unittest.TestCase):
    def run_script(self, *args):
        cache = tempfile.mkdtemp(prefix='dm_pinned_test_')
        p = subprocess.run(['bash', SCRIPT] + list(args), capture_output=True, text=True, timeout=60,
                           env=dict(os.environ, XDG_CACHE_HOME=cache))
        made = os.listdir(os.path.join(cache, 'dem_mobility')) if os.path.isdir(os.path.join(cache, 'dem_mobility')) else []
        return p, made

    def test_refusals_exit_2_naming_what_is_wrong_and_build_nothing(self):
        for args, said in ((['--', ], 'no command to run'),
                           (['no-such-commit', '--', 'true'], 'no-such-commit: not a commit of %s' % ROOT),
                           (['true'], 'usage: scripts/pinned.sh'),
                           ([], 'usage: scripts/pinned.sh')):
            p, made = self.run_script(*args)
            self.assertEqual(p.returncode, 2, (args, p.stderr))
            self.assertIn(said, p.stderr, args)
            self.assertEqual(made, [], args)

    def test_list_with_no_pinned_build_lists_none(self):
        p, made = self.run_script('--list')
        self.assertEqual((p.returncode, p.stdout), (0, ''), p.stderr)


if __name__ == '__main__':
    unittest.main()
