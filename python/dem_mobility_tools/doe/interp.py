"""Bilinear interpolation of a speed table over (grade, cone index) at every cell of a map
(paper section 5, step 2): scipy's RegularGridInterpolator (linear), a 1100 x 1100 map in a
handful of array passes.

The table is speed[i][j] at grades[i] [deg] and cone_indices[j] [psi], both rising. A cell whose
grade or CI lies outside the table's range has no value (NaN): the table says nothing there, and
a map must not pretend it does. `clamp_ci` (off by default) takes a CI above the table's highest
as that highest (soil stronger than the strongest simulated behaves at least as well: a
conservative speed); a CI below the lowest keeps no value (softer soil than any simulated could
be slower than the softest: taking its speed would be optimistic); grades are never clamped.
"""
import numpy as np
from scipy.interpolate import RegularGridInterpolator


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
    inside = (g >= gx[0]) & (g <= gx[-1]) & (ci >= cx[0]) & (ci <= cx[-1])   # (False where NaN)
    # an axis of one value is left out (the table is constant along it): RegularGridInterpolator
    # gives no value on a 1 x 1 grid
    axes = [(axis, np.where(inside, x, axis[0])) for axis, x in ((gx, g), (cx, ci)) if axis.size > 1]
    if not axes:
        return np.where(inside, s[0, 0], np.nan)
    table = RegularGridInterpolator(tuple(a for a, _ in axes), s.reshape([a.size for a, _ in axes]),
                                    method='linear', bounds_error=False, fill_value=np.nan)
    return np.where(inside, table(np.stack([x for _, x in axes], axis=-1)), np.nan)
