"""Bilinear interpolation of a speed table over (grade, cone index) at every cell of a map
(paper section 5, step 2), vectorised with numpy: a 1100 x 1100 map is a handful of array passes.

The table is speed[i][j] at grades[i] [deg] and cone_indices[j] [psi], both rising. A cell whose
grade or CI lies outside the table's range has no value (NaN): the table says nothing there, and
a map must not pretend it does. `clamp_ci` (off by default) takes a CI above the table's highest
as that highest (soil stronger than the strongest simulated behaves at least as well: a
conservative speed); a CI below the lowest keeps no value (softer soil than any simulated could
be slower than the softest: taking its speed would be optimistic); grades are never clamped.
"""
import numpy as np


def bilinear(grades, cone_indices, speed, g, ci, clamp_ci=False):
    """The table at the points (g, ci) (arrays of one shape); NaN outside the table and where an
    input is NaN. A table of one grade or one CI interpolates along the other axis only."""
    gx = np.asarray(grades, dtype=float)
    cx = np.asarray(cone_indices, dtype=float)
    s = np.asarray(speed, dtype=float)
    if s.shape != (gx.size, cx.size):
        raise ValueError('the table is %s, the axes %d grades x %d cone indices' % (s.shape, gx.size, cx.size))
    g = np.asarray(g, dtype=float)
    ci = np.asarray(ci, dtype=float)
    if clamp_ci:
        ci = np.minimum(ci, cx[-1])
    inside = (g >= gx[0]) & (g <= gx[-1]) & (ci >= cx[0]) & (ci <= cx[-1])

    def locate(axis, x):
        if axis.size == 1:
            return np.zeros(x.shape, dtype=np.intp), np.zeros(x.shape)
        k = np.clip(np.searchsorted(axis, x, side='right') - 1, 0, axis.size - 2)
        t = (x - axis[k]) / (axis[k + 1] - axis[k])
        return k, t

    gi, tg = locate(gx, np.where(inside, g, gx[0]))
    cj, tc = locate(cx, np.where(inside, ci, cx[0]))
    gi1 = np.minimum(gi + 1, gx.size - 1)
    cj1 = np.minimum(cj + 1, cx.size - 1)
    v = ((1 - tg) * (1 - tc) * s[gi, cj] + tg * (1 - tc) * s[gi1, cj] +
         (1 - tg) * tc * s[gi, cj1] + tg * tc * s[gi1, cj1])
    return np.where(inside, v, np.nan)
