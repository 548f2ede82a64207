"""Unit tests of dem_mobility_tools.doe.interp: bilinear interpolation is exact on a plane (and on the
bilinear a + b g + c CI + d g CI inside each table cell), NaN outside (the map timing is a benchmark).

    PYTHONPATH=python python3 -m unittest discover -s test/python -v      (from the repository root)
"""
import os
import unittest

import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
from dem_mobility_tools.doe import interp, plan

G, C = np.array(plan.PAPER_GRADES), np.array(plan.PAPER_CONE_INDICES)   # uneven CI spacing


class Bilinear(unittest.TestCase):
    def test_exact_on_a_plane_at_random_points(self):
        plane = lambda g, c: 3.0 - 0.25 * g + 0.04 * c  # noqa: E731
        table = plane(G[:, None], C[None, :])
        rng = np.random.default_rng(3)
        g = rng.uniform(G[0], G[-1], 10000)
        c = rng.uniform(C[0], C[-1], 10000)
        np.testing.assert_allclose(interp.bilinear(G, C, table, g, c), plane(g, c), rtol=0, atol=1e-12)

    def test_exact_at_the_nodes_and_on_a_bilinear_cell(self):
        rng = np.random.default_rng(5)
        table = rng.uniform(0, 25, (G.size, C.size))
        gg, cc = np.meshgrid(G, C, indexing='ij')
        np.testing.assert_array_equal(interp.bilinear(G, C, table, gg, cc), table)
        # inside one cell the interpolant of a + b g + c CI + d g CI is that function
        f = lambda g, c: 1.0 + 0.3 * g - 0.02 * c + 0.001 * g * c  # noqa: E731
        t = f(G[:, None], C[None, :])
        g, c = rng.uniform(G[4], G[5], 500), rng.uniform(C[7], C[8], 500)
        np.testing.assert_allclose(interp.bilinear(G, C, t, g, c), f(g, c), atol=1e-12)

    def test_outside_the_table_is_nan_unless_the_ci_is_clamped_from_above(self):
        table = np.ones((G.size, C.size))
        table[:, -1] = 2.0  # the strongest soil's column
        out = interp.bilinear(G, C, table, np.array([40.0, 10.0, 10.0, np.nan]), np.array([100.0, 20.0, 400.0, 100.0]))
        self.assertTrue(np.isnan(out).all())
        # a CI above the table takes its strongest column; one below it (softer than any case) none
        clamped = interp.bilinear(G, C, table, np.array([40.0, 10.0, 10.0]), np.array([100.0, 20.0, 400.0]),
                                  clamp_ci=True)
        np.testing.assert_array_equal(clamped, [np.nan, np.nan, 2.0])

    def test_a_hand_computed_value(self):
        # grades 0, 10 and CI 100, 200; at grade 2.5 (t 0.25) and CI 175 (u 0.75):
        # 0.75 * 0.25 * 1 + 0.25 * 0.25 * 5 + 0.75 * 0.75 * 3 + 0.25 * 0.75 * 11 = 4.25 (exact in binary)
        out = interp.bilinear([0.0, 10.0], [100.0, 200.0], [[1.0, 3.0], [5.0, 11.0]], np.array([2.5]),
                              np.array([175.0]))
        self.assertEqual(out[0], 4.25)

    def test_a_one_cell_table_holds_its_value_at_its_point_only(self):
        out = interp.bilinear([12.0], [30.0], [[2.0]], np.array([12.0, 12.0, 12.5, np.nan]),
                              np.array([30.0, 31.0, 30.0, 30.0]))
        np.testing.assert_array_equal(out, [2.0, np.nan, np.nan, np.nan])

    def test_a_single_grade_interpolates_along_ci(self):
        out = interp.bilinear([12.0], [30.0, 50.0], [[2.0, 6.0]], np.array([12.0, 12.0]), np.array([40.0, 50.0]))
        np.testing.assert_allclose(out, [4.0, 6.0])

    def test_a_wrong_table_shape_is_refused(self):
        with self.assertRaisesRegex(ValueError, 'grades'):
            interp.bilinear(G, C, np.ones((3, 3)), np.zeros(1), np.zeros(1))


if __name__ == '__main__':
    unittest.main()
