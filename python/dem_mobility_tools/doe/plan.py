"""The design of experiments over grade x cone index: the grid, the order the cases run in, and the
cases whose outcome the finished ones already fix (docs/doe.md).

Speed-made-good falls with grade and rises with cone index. So a case is fixed without a run when
  - an easier case (grade no higher, CI no lower) was stuck (no_go): this one is stuck too, or
  - a harder case (grade no lower, CI no higher) reached the command (command_limited): this one too,
and no finished case contradicts that bound (a harder case that moved, for an implied no-go; an
easier case that stayed under the command, for an implied command limit): where the bounds
disagree (the simulated speeds are not monotone there, e.g. near a threshold), the case runs.

The order brings those bounds early: a coarse grid first (each axis's ends, then its middle, then
the middles of the halves ...: the bisection order of each axis), so that a stuck or command-limited
coarse case fixes the finer cases around it before they come up. The order is fixed (it does not
depend on the outcomes), so that a job array submitted at once (Slurm) runs the same cases in the
same order as the local pool; a case is checked against the finished ones when its turn comes.

Refinement (doe run --refine N, beyond the paper): once the grid is finished, N new grid lines
go where the speed changes fastest between neighbouring cases, each at the midpoint of the pair
of neighbouring grades (or soil cone indices) across which the speed jumps most; their cases run
like the others (pruned where the finished ones fix them), and the table keeps a full grid, so
that the map's bilinear interpolation stays what it is.
"""
import math

# the paper's grid (section 6): 14 grades and the 12 CIs of table 3, CI 300 being the rigid road
PAPER_GRADES = [3.0 * i for i in range(14)]
PAPER_CONE_INDICES = [30.0, 40.0, 50.0, 60.0, 70.0, 80.0, 100.0, 120.0, 150.0, 200.0, 242.0, 300.0]
ROAD_CONE_INDEX = 300.0

NO_GO = 'no_go'
COMMAND_LIMITED = 'command_limited'


class PlanError(ValueError):
    pass


def bisection_levels(n):
    """Each index of an axis of n values gets the level at which a bisection of the axis first
    reaches it: the two ends at 0, the middle at 1, the quarters at 2, ..."""
    level = [None] * n
    if n == 0:
        return level
    level[0] = level[n - 1] = 0
    spans, depth = [(0, n - 1)], 1
    while spans:
        nxt = []
        for lo, hi in spans:
            if hi - lo < 2:
                continue
            mid = (lo + hi) // 2
            if level[mid] is None:
                level[mid] = depth
            nxt += [(lo, mid), (mid, hi)]
        spans, depth = nxt, depth + 1
    return level


class Grid:
    """G grades [deg] x C cone indices [psi], both strictly rising."""

    def __init__(self, grades, cone_indices):
        for name, axis in (('grades', grades), ('cone indices', cone_indices)):
            if not axis:
                raise PlanError('the grid has no %s (an empty grid)' % name)
            if any(not isinstance(x, (int, float)) or not math.isfinite(x) for x in axis):
                raise PlanError('%s: expected numbers, got %r' % (name, axis))
            if any(b <= a for a, b in zip(axis, axis[1:])):
                raise PlanError('%s must rise strictly, got %r' % (name, axis))
        if grades[0] < 0 or grades[-1] >= 90:
            raise PlanError('grades must lie in [0, 90) deg, got %r' % grades)
        if cone_indices[0] <= 0:
            raise PlanError('cone indices must be positive, got %r' % cone_indices)
        self.grades = [float(g) for g in grades]
        self.cone_indices = [float(c) for c in cone_indices]

    def cells(self):
        return [(i, j) for i in range(len(self.grades)) for j in range(len(self.cone_indices))]

    def order(self):
        """The run order of the cells (i grade index, j CI index): by the coarser of the two
        bisection levels, then the finer, then from the hardest corner (high grade, low CI) and the
        easiest (low grade, high CI) inwards, alternately, so that both kinds of bound come early."""
        lg, lc = bisection_levels(len(self.grades)), bisection_levels(len(self.cone_indices))
        ng, nc = len(self.grades), len(self.cone_indices)

        def key(cell):
            i, j = cell
            hard = (ng - 1 - i) + j          # 0 at the hardest corner
            easy = i + (nc - 1 - j)          # 0 at the easiest
            return (max(lg[i], lc[j]), lg[i] + lc[j], min(hard, easy), i, j)
        return sorted(self.cells(), key=key)


def implied(cell, finished):
    """What the finished cases say of `cell` (i, j): (status, value, by) with status NO_GO or
    COMMAND_LIMITED and `by` the cell that fixes it, or None when it must run.

    finished: {(i, j): (status, speed_made_good)} of the cases simulated so far (never the implied
    ones: a bound rests on runs only)."""
    i, j = cell
    stuck_by, limited_by, contradict_stuck, contradict_limited = [], [], False, False
    for (a, b), (status, speed) in finished.items():
        easier = a <= i and b >= j
        harder = a >= i and b <= j
        if easier and status == NO_GO:
            stuck_by.append((a, b))
        if harder and status == COMMAND_LIMITED:
            limited_by.append(((a, b), speed))
        if harder and not (status == NO_GO or speed == 0.0):
            contradict_stuck = True      # a harder case moved
        if easier and status != COMMAND_LIMITED:
            contradict_limited = True    # an easier case stayed under the command
    if stuck_by and limited_by:
        return None                      # the two kinds of bound disagree
    if stuck_by and not contradict_stuck:
        by = min(stuck_by, key=lambda c: (abs(c[0] - i) + abs(c[1] - j), c))
        return NO_GO, 0.0, by
    if limited_by and not contradict_limited:
        # the slowest of the harder command-limited cases (a bound from below)
        by, speed = min(limited_by, key=lambda x: (x[1], abs(x[0][0] - i) + abs(x[0][1] - j), x[0]))
        return COMMAND_LIMITED, speed, by
    return None


def replay(grid, outcome_of):
    """Runs the plan against `outcome_of(cell) -> (status, speed)` (a model or a table of results):
    the cells in order, each either simulated or implied. Returns (simulated, implied) as ordered
    lists of (cell, status, speed[, by])."""
    finished, sim, imp = {}, [], []
    for cell in grid.order():
        x = implied(cell, finished)
        if x is None:
            status, speed = outcome_of(cell)
            finished[cell] = (status, speed)
            sim.append((cell, status, speed))
        else:
            imp.append((cell,) + x)
    return sim, imp


def refinements(grades, cone_indices, speed, count, min_grade_step=1.0, min_ci_step=5.0,
                road_ci=ROAD_CONE_INDEX):
    """Up to `count` new grid lines where speed-made-good changes fastest between neighbours:
    [(axis 'grade_deg' or 'cone_index_psi', value, (lo, hi), jump)], the largest jump first. A pair of
    neighbouring grades (cone indices) is split at its midpoint; its jump is the largest |speed
    difference| across it over the other axis. A pair whose halves would be narrower than the
    minimum step (1 deg, 5 psi) is not split, nor the pair between the strongest soil and the
    road's column (CI road_ci: a rigid road, no soil between them)."""
    g, c = list(grades), list(cone_indices)
    candidates = []
    for i in range(len(g) - 1):
        if g[i + 1] - g[i] >= 2.0 * min_grade_step:
            jump = max(abs(speed[i + 1][j] - speed[i][j]) for j in range(len(c)))
            candidates.append((jump, 'grade_deg', 0.5 * (g[i] + g[i + 1]), (g[i], g[i + 1])))
    for j in range(len(c) - 1):
        if c[j + 1] >= road_ci or c[j + 1] - c[j] < 2.0 * min_ci_step:
            continue
        jump = max(abs(speed[i][j + 1] - speed[i][j]) for i in range(len(g)))
        candidates.append((jump, 'cone_index_psi', 0.5 * (c[j] + c[j + 1]), (c[j], c[j + 1])))
    candidates.sort(key=lambda x: (-x[0], x[1], x[2]))
    return [(axis, value, between, jump) for jump, axis, value, between in candidates[:max(0, count)] if jump > 0.0]
