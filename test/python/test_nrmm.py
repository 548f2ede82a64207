"""Unit tests of dem_mobility_tools.terramechanics.nrmm against the figures worked out independently in
../shared/reference/nrmm-baseline.md (the M998 worked example of section 3, the VTI sanity table of
section 4.3 and the illustrative speed table of section 5), and its refusals of bad input.

    PYTHONPATH=python python3 -m unittest discover -s test/python -v      (from the repository root)
"""
import math
import os
import tempfile
import unittest

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
from dem_mobility_tools.terramechanics import nrmm

HP = 745.699872
# the M998 of nrmm-baseline.md: 7,700 lb, 37 x 12.5 in tires, 16 in clearance, 150 hp, automatic;
# section 5's assumptions: power-limited push eta P / V with eta 0.75, 55 mph top speed, slip cap 0.5
M998 = dict(gross_mass=7700 * 0.45359237, axles=2, tires=4, tire_diameter=0.94, tire_width=0.3175,
            tire_section_height=0.26, deflection_ratio=0.15, ground_clearance=16 * 0.0254,
            transmission='automatic', grousers=False, engine_power=150 * HP, powertrain='(given)',
            final_drive_ratio=0.2, driveline_efficiency=0.75, max_speed=55 * 0.44704, slip_cap=0.5,
            gross_traction_cap=1.0)
# a constant-power WOT curve at the drive shaft, P / omega, sampled finely (capped at standstill)
CONSTANT_POWER = [(w, min(2e4, 150 * HP / w)) for w in [0.5 * i for i in range(1, 4001)]]


def m998(**change):
    return nrmm.Vehicle(dict(M998, **change), wot=CONSTANT_POWER)


class MobilityIndex(unittest.TestCase):
    def test_the_worked_m998_example(self):
        v = m998()
        self.assertAlmostEqual(v.mobility_index(), 43.9, delta=0.05)
        self.assertAlmostEqual(v.vci1(), 19.4, delta=0.05)
        self.assertAlmostEqual(v.vci50(), 45.2, delta=0.1)

    def test_more_tire_deflection_lowers_vci1(self):
        # DCF = (0.15 / (delta/h))^0.25: 18.1 / 17.1 / 15.7 psi at 0.20 / 0.25 / 0.35
        for ratio, vci in ((0.20, 18.1), (0.25, 17.1), (0.35, 15.7)):
            self.assertAlmostEqual(m998(deflection_ratio=ratio).vci1(), vci, delta=0.05)

    def test_the_weight_factor_is_continuous_at_its_breakpoints(self):
        # WF's branches meet at 2, 13.5 and 20 kips per axle to within 1.1 % (0.553 at the first:
        # the "0.533" of two codes would jump by 4.5 %), so MI jumps by under 1.5 % there
        for kips in (2.0, 13.5, 20.0):
            lo = m998(gross_mass=(kips - 1e-6) * 2000 * 0.45359237).mobility_index()
            hi = m998(gross_mass=(kips + 1e-6) * 2000 * 0.45359237).mobility_index()
            self.assertLess(abs(hi - lo), 0.015 * lo, 'at %g kips per axle: %g -> %g' % (kips, lo, hi))


class Vti(unittest.TestCase):
    def test_the_hmmwv_wheel_sanity_table(self):
        # W 8.56 kN per wheel, b 0.3175 m, d 0.94 m, delta/h 0.15 (nrmm-baseline.md section 4.3)
        v = m998(gross_mass=4 * 8560.0 / nrmm.G)
        # as printed (strings: a float would drop the trailing zeros of 0.50 and 0.030)
        table = {20: ('4.9', '0.39', '-0.16', '0.50'), 30: ('7.4', '0.15', '0.07', '0.23'),
                 40: ('9.9', '0.074', '0.23', '0.13'), 60: ('14.8', '0.030', '0.44', '0.062'),
                 100: ('24.7', '0.012', '0.66', '0.027')}
        # each entry as the reference prints it: within half a unit of its last digit
        def half_unit(printed):
            return 0.5 * 10 ** -(len(printed.split('.')[1]) if '.' in printed else 0) + 1e-12
        for ci, (n_c, s_sp, dp20, mr) in table.items():
            got = v.vti(ci)
            for what, value, printed in (('N_c', got[0], n_c), ('S_sp', got[1], s_sp),
                                         ('DP/W at 20 %', v.net_pull(ci, 0.2), dp20), ('MR/W', got[2], mr)):
                self.assertLessEqual(abs(value - float(printed)), half_unit(printed),
                                     '%s at CI %g: %.5f does not print as %s' % (what, ci, value, printed))

    def test_net_pull_is_zero_at_the_self_propelled_slip(self):
        v = m998()
        for ci in (25, 60, 200):
            self.assertAlmostEqual(v.net_pull(ci, v.vti(ci)[1]), 0.0, places=12)


class Speed(unittest.TestCase):
    def test_the_illustrative_speed_table(self):
        # km/h against RCI and grade in per cent (nrmm-baseline.md section 5; None: NO-GO)
        table = {20: [10.7, 8.2, None, None, None, None, None],
                 25: [21.1, 17.0, 13.8, 11.1, None, None, None],
                 30: [33.2, 26.2, 21.3, 17.5, 14.4, 9.5, None],
                 40: [62.6, 44.5, 34.3, 27.7, 23.0, 16.6, 12.1],
                 60: [88.5, 76.1, 52.4, 40.0, 32.3, 23.2, 17.9],
                 100: [88.5, 88.5, 68.7, 49.4, 38.7, 27.2, 21.1]}
        v = m998()
        for ci, row in table.items():
            for pct, want in zip((0, 5, 10, 15, 20, 30, 40), row):
                got = v.speed(math.degrees(math.atan(pct / 100.0)), ci)
                if want is None:
                    self.assertEqual(got['status'], 'no_go', (ci, pct, got))
                    self.assertEqual(got['speed'], 0.0)
                else:
                    self.assertAlmostEqual(got['speed'] * 3.6, want, delta=0.15, msg='CI %g, %g %%' % (ci, pct))
                    self.assertEqual(got['status'], 'command_limited' if want == 88.5 else 'power_limited')

    def test_below_vci1_is_no_go_and_the_power_limit_is_eta_p_over_the_push(self):
        v = m998()
        self.assertEqual(v.speed(0.0, 19.0)['limit'], 'vci1')
        # on strong soil at 10 deg: V = (1 - s) eta P / (W sin + MR W cos)
        r = v.speed(10.0, 250.0)
        th = math.radians(10.0)
        force = v.mass * nrmm.G * (math.sin(th) + r['motion_resistance'] * math.cos(th))
        self.assertAlmostEqual(r['speed'], (1 - r['slip']) * 0.75 * 150 * HP / force, delta=0.01)

    def test_speed_falls_with_grade_and_rises_with_cone_index(self):
        v = nrmm.Vehicle.load(os.path.join(ROOT, 'config', 'vehicles', 'hmmwv', 'nrmm.yaml'))
        speeds, _ = v.table([0, 6, 12, 18, 24, 30, 36], [30, 50, 70, 100, 150, 200, 300])
        for g in range(len(speeds)):
            for c in range(len(speeds[g])):
                if g:
                    self.assertLessEqual(speeds[g][c], speeds[g - 1][c])
                if c:
                    self.assertGreaterEqual(speeds[g][c], speeds[g][c - 1])


class BadInput(unittest.TestCase):
    def test_refusals_name_the_file_and_the_key(self):
        with tempfile.TemporaryDirectory() as tmp:
            path = os.path.join(tmp, 'v.yaml')
            with open(path, 'w') as fh:
                fh.write('gross_mass: -5\n')
            with self.assertRaisesRegex(nrmm.NrmmError, 'v.yaml: missing key'):
                nrmm.Vehicle.load(path)
            with self.assertRaisesRegex(nrmm.NrmmError, 'cannot read'):
                nrmm.Vehicle.load(os.path.join(tmp, 'none.yaml'))
        with self.assertRaisesRegex(nrmm.NrmmError, 'gross_mass'):
            m998(gross_mass=-5)
        with self.assertRaisesRegex(nrmm.NrmmError, 'transmission'):
            m998(transmission='cvt')
        with self.assertRaisesRegex(nrmm.NrmmError, 'unknown key'):
            nrmm.Vehicle(dict(M998, wheels=4), wot=CONSTANT_POWER)
        with self.assertRaisesRegex(nrmm.NrmmError, 'cone index'):
            m998().speed(12.0, float('nan'))
        with self.assertRaisesRegex(nrmm.NrmmError, 'grade'):
            m998().speed(95.0, 100.0)


if __name__ == '__main__':
    unittest.main()
