"""The NRMM-style empirical model: speed-made-good of a wheeled vehicle against cone index and
positive grade, a model of its own beside the physics one (docs/doe.md, "The NRMM-style model"; the relations, their
sources and confidence: ../shared/reference/nrmm-baseline.md).

- Go/no-go: the mobility index MI (Kennedy & Rush; FM 5-430-00-1) and the one-pass vehicle cone
  index VCI1 (Priddy & Willoughby 2006, with 3.74 in the denominator and the deflection factor DCF).
  RCI = CI (our soil does not remold: RI = 1). CI < VCI1 is NO-GO on the first pass.
- Traction and resistance: the ERDC VTI fine-grained relations (Dettwiller et al. 2018 eqs. 1-6, as
  MAVS codes them, S_sp with its + 0.005): clay numeric N_c, self-propelled slip S_sp, net pull
  DP/W(s) = 0.5 (1 + b/d)^0.25 log10(s / S_sp), powered motion resistance MR/W = 12/N_c^2 + 0.007.
- Speed on a grade theta (nrmm-baseline.md section 5): the net pull must carry the grade,
  DP/W = tan(theta) at the normal load W cos(theta); the slip that gives it must stay under the cap
  and the gross traction DP/W + MR/W under its cap, else NO-GO. The wheels must then push
  F = W sin(theta) + MR/W W cos(theta): the largest rim speed at which the WOT curve (the physics
  model's own, at the drive shaft, through the final drive) gives F, times (1 - slip), is the speed,
  capped at the driver's command limit.

Everything is SI at the interface (CI in psi, as the maps and the DOE give it); the MI is computed
in lb, in and hp as its fits want.
"""
import math
import os

import yaml

from . import wheel_numerics
from ..runs import read_result

LB = 0.45359237           # kg
INCH = 0.0254             # m
HP = 745.699872           # W
G = 9.81                  # m/s^2 (the physics model's gravity)

REQUIRED = ('gross_mass', 'axles', 'tires', 'tire_diameter', 'tire_width', 'tire_section_height',
            'deflection_ratio', 'ground_clearance', 'transmission', 'grousers', 'engine_power', 'powertrain',
            'final_drive_ratio', 'driveline_efficiency', 'max_speed', 'slip_cap', 'gross_traction_cap')


class NrmmError(ValueError):
    pass


def _positive(d, key, path, upper=None):
    v = d[key]
    if isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(v) or v <= 0 or \
            (upper is not None and v > upper):
        raise NrmmError('%s: %s: expected a number in (0, %s], got %r' % (path, key, upper or 'inf', v))
    return float(v)


class Vehicle:
    """A vehicle's NRMM inputs (config/vehicles/<name>/nrmm.yaml) and its WOT curve."""

    def __init__(self, d, path='<dict>', wot=None):
        unknown = sorted(set(d) - set(REQUIRED))
        missing = [k for k in REQUIRED if k not in d]
        if unknown:
            raise NrmmError('%s: unknown key(s) %s' % (path, ', '.join(unknown)))
        if missing:
            raise NrmmError('%s: missing key(s) %s' % (path, ', '.join(missing)))
        self.path = path
        self.mass = _positive(d, 'gross_mass', path)
        self.axles = int(_positive(d, 'axles', path))
        self.tires = int(_positive(d, 'tires', path))
        self.d = _positive(d, 'tire_diameter', path)
        self.b = _positive(d, 'tire_width', path)
        self.h = _positive(d, 'tire_section_height', path)
        self.deflection = _positive(d, 'deflection_ratio', path, 0.9)
        self.clearance = _positive(d, 'ground_clearance', path)
        if d['transmission'] not in ('automatic', 'manual'):
            raise NrmmError("%s: transmission: 'automatic' or 'manual', got %r" % (path, d['transmission']))
        self.automatic = d['transmission'] == 'automatic'
        if not isinstance(d['grousers'], bool):
            raise NrmmError('%s: grousers: true or false, got %r' % (path, d['grousers']))
        self.grousers = d['grousers']
        self.power = _positive(d, 'engine_power', path)
        self.final_drive = _positive(d, 'final_drive_ratio', path)
        self.efficiency = _positive(d, 'driveline_efficiency', path, 1.0)
        self.max_speed = _positive(d, 'max_speed', path)
        self.slip_cap = _positive(d, 'slip_cap', path, 1.0)
        self.gt_cap = _positive(d, 'gross_traction_cap', path)
        if wot is None:
            pt = d['powertrain']
            pt_path = pt if os.path.isabs(pt) else os.path.join(os.path.dirname(path), pt)
            try:
                with open(pt_path) as fh:
                    wot = yaml.safe_load(fh)['wot_torque']
            except (OSError, KeyError, TypeError, yaml.YAMLError) as e:
                raise NrmmError('%s: powertrain: cannot read wot_torque from %s (%s)' % (path, pt_path, e))
        pts = [(float(w), float(t)) for w, t in wot]
        if len(pts) < 2 or any(b[0] <= a[0] for a, b in zip(pts, pts[1:])):
            raise NrmmError('%s: powertrain: wot_torque needs rising drive-shaft speeds' % path)
        self.wot = pts

    @classmethod
    def load(cls, path):
        d, why = read_result(path)
        if d is None:
            raise NrmmError('cannot read the vehicle file: %s' % why)
        return cls(d, path)

    # -- go/no-go: mobility index and vehicle cone index ------------------------------------------
    def mobility_index(self):
        """MI = [CPF WF / (TF GF) + WLF - CF] EF TrF, in lb, in and hp (nrmm-baseline.md section 2)."""
        w_lb = self.mass / LB
        b_in, d_in = self.b / INCH, self.d / INCH
        cpf = w_lb / (self.tires * b_in * 0.5 * d_in)
        x = w_lb / 1000.0 / self.axles                       # kips per axle
        if x < 2.0:
            wf = 0.553 * x
        elif x < 13.5:
            wf = 0.033 * x + 1.050
        elif x < 20.0:
            wf = 0.142 * x - 0.420
        else:
            wf = 0.278 * x - 3.115
        tf = (10.0 + b_in) / 100.0
        gf = 1.05 if self.grousers else 1.0
        wlf = w_lb / 1000.0 / (2.0 * self.axles)
        cf = self.clearance / INCH / 10.0
        ef = 1.0 if self.power / HP / (w_lb / 2000.0) >= 10.0 else 1.05
        trf = 1.0 if self.automatic else 1.05
        return (cpf * wf / (tf * gf) + wlf - cf) * ef * trf

    def dcf(self):
        return (0.15 / self.deflection) ** 0.25

    def vci1(self):
        """The one-pass vehicle cone index [psi] (Priddy & Willoughby 2006)."""
        mi = self.mobility_index()
        if mi <= 115.0:
            return (11.48 + 0.2 * mi - 39.2 / (mi + 3.74)) * self.dcf()
        return 4.1 * mi ** 0.446 * self.dcf()

    def vci50(self):
        """The fifty-pass vehicle cone index [psi] (MI <= 115 branch; nrmm-baseline.md section 3)."""
        mi = self.mobility_index()
        return 28.23 + 0.43 * mi - 92.67 / (mi + 3.67)

    # -- traction: VTI fine-grained -------------------------------------------------------------
    def wheel_load(self, grade_rad=0.0):
        """The normal load of one wheel [N], the vehicle's weight shared equally."""
        return self.mass * G * math.cos(grade_rad) / self.tires

    def vti(self, ci_psi, grade_rad=0.0):
        """The VTI numerics of one wheel (dm_sweep.wheel_numerics, the single-wheel rig's reference
        band): N_c, S_sp and the powered motion resistance MR/W."""
        x = wheel_numerics.vti(ci_psi, self.b, self.d, self.wheel_load(grade_rad), self.deflection)
        return x['nc'], x['ssp'], x['mr_powered']

    def net_pull(self, ci_psi, slip, grade_rad=0.0):
        """DP/W at a slip (net traction coefficient; negative below the self-propelled slip; uncapped)."""
        n_c, s_sp, _ = self.vti(ci_psi, grade_rad)
        return wheel_numerics.vti_dp_over_w(slip, n_c, self.b, self.d, s_sp, cap=False)

    # -- the WOT tractive force -----------------------------------------------------------------
    def wot_torque(self, w):
        pts = self.wot
        if w <= pts[0][0]:
            return pts[0][1]
        for (w0, t0), (w1, t1) in zip(pts, pts[1:]):
            if w <= w1:
                return t0 + (t1 - t0) * (w - w0) / (w1 - w0)
        return pts[-1][1]

    def tractive_force(self, rim_speed):
        """The wheels' total push at a rim speed [N] under wide-open throttle."""
        w_ds = rim_speed / (0.5 * self.d * self.final_drive)
        return self.efficiency * self.wot_torque(w_ds) / self.final_drive / (0.5 * self.d)

    def top_rim_speed(self, force):
        """The largest rim speed at which the WOT curve gives `force`, or None."""
        r, fd = 0.5 * self.d, self.final_drive
        best = None
        pts = self.wot
        for (w0, t0), (w1, t1) in zip(pts, pts[1:]):
            f0, f1 = (self.efficiency * t / fd / r for t in (t0, t1))
            if max(f0, f1) < force:
                continue
            # the highest point of this segment with F >= force
            if f1 >= force:
                w = w1
            else:
                w = w0 + (w1 - w0) * (f0 - force) / (f0 - f1)
            v = w * r * fd
            best = v if best is None else max(best, v)
        return best

    # -- speed-made-good ------------------------------------------------------------------------
    def speed(self, grade_deg, ci_psi):
        """Speed-made-good [m/s] with its status and the figures behind it."""
        if not (math.isfinite(grade_deg) and 0.0 <= grade_deg < 90.0):
            raise NrmmError('grade %r deg: expected 0 <= grade < 90' % grade_deg)
        if not (math.isfinite(ci_psi) and ci_psi > 0.0):
            raise NrmmError('cone index %r psi: expected a positive number' % ci_psi)
        th = math.radians(grade_deg)
        out = {'grade_deg': grade_deg, 'cone_index_psi': ci_psi, 'vci1': self.vci1()}
        n_c, s_sp, mr = self.vti(ci_psi, th)
        out.update(clay_numeric=n_c, self_propelled_slip=s_sp, motion_resistance=mr)
        if ci_psi < out['vci1']:
            return dict(out, speed=0.0, status='no_go', limit='vci1', slip=None)
        need = math.tan(th)                                    # net pull per normal load
        slip = s_sp * 10.0 ** (need / (0.5 * (1.0 + self.b / self.d) ** 0.25))
        out['slip'] = slip
        if slip > self.slip_cap:
            return dict(out, speed=0.0, status='no_go', limit='slip')
        if need + mr > self.gt_cap:
            return dict(out, speed=0.0, status='no_go', limit='gross_traction')
        force = self.mass * G * (math.sin(th) + mr * math.cos(th))
        out['tractive_force'] = force
        v_rim = self.top_rim_speed(force)
        if v_rim is None:
            return dict(out, speed=0.0, status='no_go', limit='power')
        v = v_rim * (1.0 - slip)
        if v >= self.max_speed:
            return dict(out, speed=self.max_speed, status='command_limited', limit='max_speed')
        return dict(out, speed=v, status='power_limited', limit='power')

    def table(self, grades_deg, cis_psi):
        """speed[g][c] [m/s] and status[g][c] over a grid."""
        rows = [[self.speed(g, c) for c in cis_psi] for g in grades_deg]
        return [[x['speed'] for x in r] for r in rows], [[x['status'] for x in r] for r in rows]
