"""Empirical wheel-on-soil relations (docs: /reference nrmm-baseline.md section 4): the ERDC VTI
fine-grained model (Dettwiller et al. 2018, eqs 1-9), the WES clay numeric (Freitag 1965 /
Turnage 1972), Brixius (1987) and Wismer & Luth (1974). They are empirical fits for pneumatic
tires, used as a REFERENCE BAND beside the DEM single-wheel rig, not as truth.

Units at the interface, the same for every function:
  ci          cone index [psi] (RCI in the critical layer; the DEM soil does not remold, RI = 1)
  b, d        tire section width and unloaded diameter [m]
  w           wheel load [N]
  dh          tire deflection over unloaded section height, delta / h [-] (0 for a rigid tire)
  s           slip, a fraction (0.2 = 20 %)
Inside, the numerics are formed as CI [kPa] b [m] d [m] / W [kN], which is dimensionless and the
same number as CI [psi] b [in] d [in] / W [lb].

A rigid tire (our simulation's) has delta = 0:
  VTI:       (1 - delta/h)^1.5 = 1: the numerics are defined; dh = 0 is the rigid reading.
  WES:       (delta/h)^0.5 = 0: N_c = 0 for every soil, which says nothing; and the baseline gives
             no closed-form pull or resistance for it (only curves). WES is reported as a numeric
             at a nominal pneumatic dh (0.15) and left out of the band.
  Brixius:   (1 + 5 delta/h) = 1: defined; dh = 0 is the rigid reading.
  Wismer-Luth: no deflection term.

All coefficients are over the wheel load W: DP/W net traction (drawbar pull), MR/W motion
resistance, GT/W gross traction = DP/W + MR/W.
"""
import math

PSI_KPA = 6.894757  # kPa per psi

NOMINAL_PNEUMATIC_DH = 0.15  # delta/h of a pneumatic tire off road (the baseline's sanity table)


def band_members(pneumatic_dh=NOMINAL_PNEUMATIC_DH):
    """The reference band's members (label, model, delta/h): VTI for the rigid tire and at a nominal
    pneumatic deflection, Brixius (bias-ply) rigid, Wismer-Luth. See reference_band()."""
    return (('VTI, rigid (delta/h 0)', 'vti', 0.0),
            ('VTI, pneumatic (delta/h %g)' % pneumatic_dh, 'vti', pneumatic_dh),
            ('Brixius bias-ply, rigid (delta/h 0)', 'brixius', 0.0),
            ('Wismer-Luth', 'wismer_luth', 0.0))


BAND_MEMBERS = band_members()


def cone_numeric(ci, b, d, w):
    """C_n = CI b d / W (Wismer-Luth, Brixius' C_n; the VTI sinkage numeric with no deflection)."""
    if not (ci > 0 and b > 0 and d > 0 and w > 0):
        raise ValueError('cone_numeric: CI, b, d and W must be positive (got %r, %r, %r, %r)' % (ci, b, d, w))
    return ci * PSI_KPA * b * d / (w * 1e-3)


# -- VTI (Dettwiller et al. 2018; MAVS src/vehicles/vti/fine_grained.cpp)

def vti_ncz(ci, b, d, w, dh=0.0):
    """Eq. 1, sinkage numeric N_cz = CI b d / [W (1 - delta/h)^1.5]."""
    if not 0.0 <= dh < 1.0:
        raise ValueError('vti_ncz: delta/h must lie in [0, 1), got %r' % dh)
    return cone_numeric(ci, b, d, w) / (1.0 - dh) ** 1.5


def vti_nc(ci, b, d, w, dh=0.0):
    """Eq. 2, clay numeric N_c = N_cz / (1 + b/d)^0.75."""
    return vti_ncz(ci, b, d, w, dh) / (1.0 + b / d) ** 0.75


def vti_ssp(nc, offset=0.005):
    """Eq. 3, self-propelled slip (net pull zero) S_sp = 21 / N_c^2.5 + offset. The MAVS code adds
    offset = 0.005 (the baseline's sanity table includes it); Dettwiller's eq. 3 and the MAVS doc
    have offset = 0."""
    return 21.0 / nc ** 2.5 + offset


def vti_mr_powered(nc):
    """Eq. 5, motion resistance of a powered wheel MR/W = 12 / N_c^2 + 0.007."""
    return 12.0 / nc ** 2 + 0.007


def vti_mr_towed(nc):
    """Eq. 7 (Dettwiller eq. 27, calibrated): towed motion resistance MR/W = 5.07 / N_c^1.71 + 0.011."""
    return 5.07 / nc ** 1.71 + 0.011


def vti_dp_over_w(s, nc, b, d, ssp, cap=True):
    """Eq. 4, net traction DP/W = 0.5 (1 + b/d)^0.25 log10(s / S_sp), for s > 0 (NaN otherwise: the
    relation has no value at zero or negative slip). Zero at s = S_sp, negative below (towing
    needed). cap: as MAVS, the gross coefficient DP/W + MR/W (powered) is capped at 1."""
    if not s > 0:
        return float('nan')
    dp = 0.5 * (1.0 + b / d) ** 0.25 * math.log10(s / ssp)
    if cap:
        dp = min(dp, 1.0 - vti_mr_powered(nc))
    return dp


def vti_gt_over_w(s, nc, b, d, ssp, cap=True, calibrated=False):
    """Eq. 6, gross traction GT/W = DP/W + MR/W (powered). calibrated: eq. 8 (Dettwiller eq. 29)
    adds 0.032 S_sp^0.547 / s^0.777 (MAVS leaves it off, and so does the band)."""
    gt = vti_dp_over_w(s, nc, b, d, ssp, cap) + vti_mr_powered(nc)
    if calibrated and s > 0:
        gt += 0.032 * ssp ** 0.547 / s ** 0.777
    return gt


def vti_sinkage_powered(ncz, ssp):
    """Eq. 9, sinkage of a powered wheel, z/d = 1.64 / (N_cz / S_sp^0.19)^1.21 (no slip term)."""
    return 1.64 / (ncz / ssp ** 0.19) ** 1.21


def vti_sinkage_towed(ncz):
    """Eq. 9, sinkage of a towed wheel, z/d = 2.66 / N_cz^1.64 - 0.0063."""
    return 2.66 / ncz ** 1.64 - 0.0063


def vti(ci, b, d, w, dh=0.0, offset=0.005):
    """The VTI numerics of one wheel on one soil: ncz, nc, ssp, mr_powered, mr_towed, sinkage
    z/d powered and towed (z_over_d_powered, z_over_d_towed)."""
    ncz = vti_ncz(ci, b, d, w, dh)
    nc = vti_nc(ci, b, d, w, dh)
    ssp = vti_ssp(nc, offset)
    return {'ncz': ncz, 'nc': nc, 'ssp': ssp, 'mr_powered': vti_mr_powered(nc), 'mr_towed': vti_mr_towed(nc),
            'z_over_d_powered': vti_sinkage_powered(ncz, ssp), 'z_over_d_towed': vti_sinkage_towed(ncz)}


# -- WES clay numeric (Freitag 1965, Turnage 1972; nrmm-baseline.md 4.2)

def wes_nc(ci, b, d, w, dh):
    """N_c = (CI b d / W) (delta/h)^0.5 / (1 + b/(2d)). A rigid tire (dh = 0) gives 0: the numeric is
    meant for pneumatic tires. Only the numeric: the baseline gives no closed-form pull for it."""
    if not 0.0 <= dh < 1.0:
        raise ValueError('wes_nc: delta/h must lie in [0, 1), got %r' % dh)
    return cone_numeric(ci, b, d, w) * math.sqrt(dh) / (1.0 + b / (2.0 * d))


# -- Brixius (1987; MAVS brixius.cpp; nrmm-baseline.md 4.4)

def brixius_bn(ci, b, d, w, dh=0.0):
    """B_n = C_n (1 + 5 delta/h) / (1 + 3 b/d)."""
    return cone_numeric(ci, b, d, w) * (1.0 + 5.0 * dh) / (1.0 + 3.0 * b / d)


def brixius(s, ci, b, d, w, dh=0.0, radial=False):
    """(MR/W, GT/W, NT/W) at slip s. Bias-ply (the standard form): MR/W = 1/B_n + 0.04 + 0.5 s /
    sqrt(B_n), GT/W = 0.88 (1 - e^(-0.1 B_n)) (1 - e^(-7.5 s)) + 0.04, NT/W = GT/W - MR/W.
    radial: the MAVS variant (0.9/B_n, 0.0325 in MR; 10.5 for 7.5 in GT, without its + 0.04)."""
    bn = brixius_bn(ci, b, d, w, dh)
    if radial:
        mr = 0.9 / bn + 0.0325 + 0.5 * s / math.sqrt(bn)
        gt = 0.88 * (1.0 - math.exp(-0.1 * bn)) * (1.0 - math.exp(-10.5 * s))
    else:
        mr = 1.0 / bn + 0.04 + 0.5 * s / math.sqrt(bn)
        gt = 0.88 * (1.0 - math.exp(-0.1 * bn)) * (1.0 - math.exp(-7.5 * s)) + 0.04
    return mr, gt, gt - mr


# -- Wismer & Luth (1974; nrmm-baseline.md 4.4)

def wismer_luth(s, ci, b, d, w):
    """(TF/W, GT/W, P/W) at slip s: towed resistance TF/W = 1.2/C_n + 0.04, gross GT/W = 0.75 (1 -
    e^(-0.3 C_n s)), net pull P/W = GT/W - TF/W."""
    cn = cone_numeric(ci, b, d, w)
    tf = 1.2 / cn + 0.04
    gt = 0.75 * (1.0 - math.exp(-0.3 * cn * s))
    return tf, gt, gt - tf


# -- the reference band

def member_curves(model, slips, ci, b, d, w, dh=0.0, offset=0.005):
    """DP/W and GT/W of one model at each slip (lists; NaN where the model has no value), and its
    towed DP/W (= -towed resistance)."""
    dp, gt = [], []
    if model == 'vti':
        v = vti(ci, b, d, w, dh, offset)
        for s in slips:
            dp.append(vti_dp_over_w(s, v['nc'], b, d, v['ssp']))
            gt.append(vti_gt_over_w(s, v['nc'], b, d, v['ssp']))
        towed = -v['mr_towed']
    elif model == 'brixius':
        for s in slips:
            _, g, n = brixius(s, ci, b, d, w, dh)
            dp.append(n)
            gt.append(g)
        towed = -brixius(0.0, ci, b, d, w, dh)[0]
    elif model == 'wismer_luth':
        for s in slips:
            _, g, n = wismer_luth(s, ci, b, d, w)
            dp.append(n)
            gt.append(g)
        towed = -wismer_luth(0.0, ci, b, d, w)[0]
    else:
        raise ValueError('unknown model %r (vti, brixius, wismer_luth)' % model)
    return {'dp_over_w': dp, 'gt_over_w': gt, 'towed_dp_over_w': towed}


def _lo_hi(columns):
    lo, hi = [], []
    for vals in zip(*columns):
        good = [v for v in vals if v == v]
        lo.append(min(good) if good else float('nan'))
        hi.append(max(good) if good else float('nan'))
    return lo, hi


def reference_band(slips, ci, b, d, w, members=BAND_MEMBERS, offset=0.005):
    """The reference band at each slip: the min and max over the members (label, model, dh) of
    DP/W (net traction) and of GT/W (gross traction, the reference for T/(W r)), members without a
    value at a slip (VTI at s <= 0) left out there. Returns {'slip', 'dp_lo', 'dp_hi', 'gt_lo',
    'gt_hi', 'towed_lo', 'towed_hi', 'members': {label: member_curves}}; towed_*: the band of a
    towed wheel's DP/W (minus each member's towed resistance: VTI eq. 7, Brixius MR/W at s = 0,
    Wismer-Luth TF/W)."""
    slips = list(slips)
    curves = {label: member_curves(model, slips, ci, b, d, w, dh, offset) for label, model, dh in members}
    dp_lo, dp_hi = _lo_hi([c['dp_over_w'] for c in curves.values()])
    gt_lo, gt_hi = _lo_hi([c['gt_over_w'] for c in curves.values()])
    towed = [c['towed_dp_over_w'] for c in curves.values()]
    return {'slip': slips, 'dp_lo': dp_lo, 'dp_hi': dp_hi, 'gt_lo': gt_lo, 'gt_hi': gt_hi,
            'towed_lo': min(towed), 'towed_hi': max(towed), 'members': curves}
