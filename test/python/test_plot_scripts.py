"""The plot scripts on good and bad input: a result of another kind or a damaged one is refused
naming the file and what is missing (exit 1, no traceback); a plot asked for in a folder that is
not there yet is written there."""
import os
import shutil
import subprocess
import sys
import tempfile
import unittest

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
TOOL = [sys.executable, '-m', 'dem_mobility_tools.plots.compression']  # dm-plot-compression


class PlotCompression(unittest.TestCase):
    def setUp(self):
        self.tmp = tempfile.mkdtemp(prefix='dm_plots_')

    def tearDown(self):
        shutil.rmtree(self.tmp, ignore_errors=True)

    def run_script(self, text, *args):
        path = os.path.join(self.tmp, 'result.yaml')
        with open(path, 'w') as fh:
            fh.write(text)
        return path, subprocess.run(TOOL + [path] + list(args), capture_output=True, text=True)

    def test_a_result_without_the_compression_keys_is_refused_naming_the_key(self):
        path, p = self.run_script('scene: road_slope\nloading: [[1000, 1200]]\nunloading: []\n')
        self.assertEqual(p.returncode, 1, p.stderr)
        self.assertIn(path, p.stderr)
        self.assertIn("no key 'bulk_density_poured'", p.stderr)
        self.assertNotIn('Traceback', p.stderr)
        path, p = self.run_script('loading: [[1000]]\nunloading: []\nbulk_density_poured: 1100\n')
        self.assertEqual(p.returncode, 1, p.stderr)
        self.assertNotIn('Traceback', p.stderr)

    def test_the_plot_goes_into_a_folder_that_is_not_there_yet(self):
        out = os.path.join(self.tmp, 'new', 'folder', 'compression.png')
        _, p = self.run_script('loading: [[1000, 1200], [30000, 1500]]\nunloading: [[10000, 1490]]\n'
                               'bulk_density_poured: 1100\nbulk_density_released: 1450\ncohesion_factor: 2\n',
                               '-o', out)
        self.assertEqual(p.returncode, 0, p.stderr)
        self.assertGreater(os.path.getsize(out), 1000)


if __name__ == '__main__':
    unittest.main()
