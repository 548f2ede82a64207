"""Unit tests of dem_mobility_tools.doe.plan: the grid's checks, the run order and the pruning by
monotone bounds (speed falls with grade, rises with cone index).

    PYTHONPATH=python python3 -m unittest discover -s test/python -v      (from the repository root)
"""
import os
import random
import unittest

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
from dem_mobility_tools.doe import plan
from dem_mobility_tools.terramechanics import nrmm


def monotone_table(ng, nc, rng, vmax=25.0):
    """A random speed table that falls with grade and rises with CI, with stuck and command-limited
    corners: v = clamp(a * CI-index - b * grade-index + noise-free offset)."""
    a, b, c0 = rng.uniform(1, 6), rng.uniform(1, 6), rng.uniform(-20, 30)
    t = {}
    for i in range(ng):
        for j in range(nc):
            v = c0 + a * j - b * i
            t[(i, j)] = (plan.NO_GO, 0.0) if v <= 0 else (plan.COMMAND_LIMITED, vmax) if v >= vmax else ('steady', v)
    return t


class Grid(unittest.TestCase):
    def test_bad_grids_are_refused(self):
        with self.assertRaisesRegex(plan.PlanError, 'empty grid'):
            plan.Grid([], [30.0])
        with self.assertRaisesRegex(plan.PlanError, 'rise strictly'):
            plan.Grid([0, 6, 3], [30.0])
        with self.assertRaisesRegex(plan.PlanError, 'positive'):
            plan.Grid([0], [0.0, 30.0])
        with self.assertRaisesRegex(plan.PlanError, r'\[0, 90\)'):
            plan.Grid([0, 95], [30.0])

    def test_the_order_holds_every_cell_once_and_begins_with_the_corners(self):
        g = plan.Grid(plan.PAPER_GRADES, plan.PAPER_CONE_INDICES)
        order = g.order()
        self.assertEqual(len(order), 14 * 12)
        self.assertEqual(sorted(order), sorted(g.cells()))
        self.assertEqual(set(order[:4]), {(0, 0), (0, 11), (13, 0), (13, 11)})

    def test_bisection_levels(self):
        self.assertEqual(plan.bisection_levels(5), [0, 2, 1, 2, 0])
        self.assertEqual(plan.bisection_levels(1), [0])


class Pruning(unittest.TestCase):
    def test_on_monotone_tables_every_implied_case_is_what_its_run_would_give(self):
        rng = random.Random(7)
        saved = 0
        for _ in range(200):
            ng, nc = rng.randint(1, 9), rng.randint(1, 9)
            t = monotone_table(ng, nc, rng)
            sim, imp = plan.replay(plan.Grid(list(range(ng)), [30.0 + 10 * j for j in range(nc)]), t.get)
            self.assertEqual(len(sim) + len(imp), ng * nc)
            for cell, status, speed, by in imp:
                self.assertEqual((status, speed), t[cell], cell)
            saved += len(imp)
        self.assertGreater(saved, 0)

    def test_a_case_whose_bounds_disagree_runs(self):
        # an easier case was stuck, but a harder one moved: not monotone here, so (1, 1) runs
        self.assertIsNone(plan.implied((1, 1), {(0, 2): (plan.NO_GO, 0.0), (2, 0): ('steady', 3.0)}))
        # an easier stuck case and a harder command-limited one: the two bounds disagree
        self.assertIsNone(plan.implied((1, 1), {(0, 2): (plan.NO_GO, 0.0), (2, 0): (plan.COMMAND_LIMITED, 25.0)}))
        # a harder command-limited case, but an easier one stayed under the command
        self.assertIsNone(plan.implied((1, 1), {(2, 0): (plan.COMMAND_LIMITED, 25.0), (0, 2): ('steady', 20.0)}))
        # and with nothing against them, the bounds do fix it
        self.assertEqual(plan.implied((1, 1), {(0, 2): (plan.NO_GO, 0.0)}), (plan.NO_GO, 0.0, (0, 2)))
        self.assertEqual(plan.implied((1, 1), {(2, 0): (plan.COMMAND_LIMITED, 24.9)}),
                         (plan.COMMAND_LIMITED, 24.9, (2, 0)))
        # a case neither easier nor harder says nothing
        self.assertIsNone(plan.implied((1, 1), {(0, 0): (plan.NO_GO, 0.0), (2, 2): (plan.COMMAND_LIMITED, 25.0)}))

    def test_on_non_monotone_tables_no_implied_case_contradicts_a_run(self):
        # random statuses: whatever is implied has a run that fixes it and no run against it
        rng = random.Random(11)
        for _ in range(300):
            ng, nc = rng.randint(1, 6), rng.randint(1, 6)
            t = {(i, j): rng.choice([(plan.NO_GO, 0.0), (plan.COMMAND_LIMITED, 25.0), ('steady', 9.0)])
                 for i in range(ng) for j in range(nc)}
            sim, imp = plan.replay(plan.Grid(list(range(ng)), [30.0 + 10 * j for j in range(nc)]), t.get)
            ran = {c: (s, v) for c, s, v in sim}
            for (i, j), status, _, by in imp:
                self.assertIn(by, ran)
                for (a, b), (s, v) in ran.items():
                    if status == plan.NO_GO and a >= i and b <= j:
                        self.assertEqual(s, plan.NO_GO)      # no harder run moved
                    if status == plan.COMMAND_LIMITED and a <= i and b >= j:
                        self.assertEqual(s, plan.COMMAND_LIMITED)

    def test_the_nrmm_table_on_the_paper_grid_saves_runs(self):
        v = nrmm.Vehicle.load(os.path.join(ROOT, 'config', 'vehicles', 'hmmwv', 'nrmm.yaml'))
        g = plan.Grid(plan.PAPER_GRADES, plan.PAPER_CONE_INDICES)

        def outcome(cell):
            r = v.speed(g.grades[cell[0]], g.cone_indices[cell[1]])
            return r['status'], r['speed']
        sim, imp = plan.replay(g, outcome)
        self.assertEqual(len(sim) + len(imp), 168)
        self.assertGreater(len(imp), 20)
        for cell, status, speed, _ in imp:
            self.assertEqual((status, speed), outcome(cell))


if __name__ == '__main__':
    unittest.main()
