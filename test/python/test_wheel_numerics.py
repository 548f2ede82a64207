"""dem_mobility_tools.terramechanics.wheel_numerics against nrmm-baseline.md section 4: the VTI and WES numbers of
the baseline's sanity table (section 4.3, a HMMWV wheel: W 8.56 kN, b 0.3175 m, d 0.94 m, delta/h
0.15; derived in the document, independently of this code), the rigid tire, the units, Brixius and
Wismer-Luth by hand, and the band.

    PYTHONPATH=python python3 -m unittest discover -s test/python -v      (from the repository root)
"""
import math
import os
import unittest

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
from dem_mobility_tools.terramechanics import wheel_numerics as wn

W, B, D, DH = 8560.0, 0.3175, 0.94, 0.15
# RCI [psi]: N_c VTI, N_c WES, S_sp, DP/W at 20 % slip, MR/W powered, MR/W calibrated (towed)
# as printed (strings: a float would drop the trailing zeros of 0.50, 0.030 and 8.0, and with
# them the digits the entries are given to)
TABLE = {20: ('4.9', '1.6', '0.39', '-0.16', '0.50', '0.34'),
         30: ('7.4', '2.4', '0.15', '0.07', '0.23', '0.18'),
         40: ('9.9', '3.2', '0.074', '0.23', '0.13', '0.11'),
         60: ('14.8', '4.8', '0.030', '0.44', '0.062', '0.062'),
         100: ('24.7', '8.0', '0.012', '0.66', '0.027', '0.032')}


def half_unit(printed):
    """Half a unit of the last printed digit of a table entry, given as printed ('0.074' -> 0.0005,
    '0.50' -> 0.005)."""
    text = printed if isinstance(printed, str) else repr(printed)
    decimals = len(text.split('.')[1]) if '.' in text else 0
    return 0.5 * 10 ** -decimals + 1e-12


class BaselineTable(unittest.TestCase):
    def assertPrinted(self, value, printed, what):
        self.assertLessEqual(abs(value - float(printed)), half_unit(printed),
                             '%s: %.5f does not print as %s' % (what, value, printed))

    def test_sanity_table(self):
        for ci, (nc, nc_wes, ssp, dp20, mr, mr_cal) in TABLE.items():
            v = wn.vti(ci, B, D, W, DH)
            self.assertPrinted(v['nc'], nc, 'N_c VTI at %g psi' % ci)
            self.assertPrinted(wn.wes_nc(ci, B, D, W, DH), nc_wes, 'N_c WES at %g psi' % ci)
            self.assertPrinted(v['ssp'], ssp, 'S_sp at %g psi' % ci)
            self.assertPrinted(wn.vti_dp_over_w(0.2, v['nc'], B, D, v['ssp']), dp20, 'DP/W(0.2) at %g psi' % ci)
            self.assertPrinted(v['mr_powered'], mr, 'MR/W powered at %g psi' % ci)
            self.assertPrinted(v['mr_towed'], mr_cal, 'MR/W calibrated at %g psi' % ci)

    def test_ssp_offset_is_the_tables(self):
        # the table's S_sp includes MAVS's + 0.005: without it 60 psi gives 0.025, not 0.030
        nc = wn.vti_nc(60, B, D, W, DH)
        self.assertAlmostEqual(wn.vti_ssp(nc, offset=0.0), 21.0 / nc ** 2.5)
        self.assertAlmostEqual(wn.vti_ssp(nc) - wn.vti_ssp(nc, 0.0), 0.005)
        self.assertGreater(abs(wn.vti_ssp(nc, 0.0) - 0.030), half_unit('0.030'))

    def test_self_propelled_slip_is_zero_pull(self):
        v = wn.vti(60, B, D, W, DH)
        self.assertAlmostEqual(wn.vti_dp_over_w(v['ssp'], v['nc'], B, D, v['ssp']), 0.0, places=12)
        self.assertLess(wn.vti_dp_over_w(0.5 * v['ssp'], v['nc'], B, D, v['ssp']), 0.0)
        self.assertTrue(math.isnan(wn.vti_dp_over_w(0.0, v['nc'], B, D, v['ssp'])))
        self.assertTrue(math.isnan(wn.vti_dp_over_w(-0.1, v['nc'], B, D, v['ssp'])))


class Units(unittest.TestCase):
    def test_cone_numeric_units(self):
        # CI [kPa] b [m] d [m] / W [kN] is the same number as CI [psi] b [in] d [in] / W [lb]
        inch, lbf = 0.0254, 4.4482216
        imperial = 60 * (B / inch) * (D / inch) / (W / lbf)
        self.assertAlmostEqual(wn.cone_numeric(60, B, D, W), imperial, delta=1e-4 * imperial)
        self.assertAlmostEqual(wn.cone_numeric(1.0, 1.0, 1.0, 1000.0), 6.894757)

    def test_inputs_checked(self):
        with self.assertRaises(ValueError):
            wn.cone_numeric(0, B, D, W)
        with self.assertRaises(ValueError):
            wn.vti_ncz(60, B, D, W, 1.0)
        with self.assertRaises(ValueError):
            wn.wes_nc(60, B, D, W, -0.1)


class RigidTire(unittest.TestCase):
    def test_vti_defined_wes_zero(self):
        self.assertEqual(wn.vti_ncz(100, 0.254, 0.97, 12066.3, 0.0), wn.cone_numeric(100, 0.254, 0.97, 12066.3))
        self.assertEqual(wn.wes_nc(100, 0.254, 0.97, 12066.3, 0.0), 0.0)
        # deflection raises VTI's numerics: a rigid tire is the weaker reading
        self.assertLess(wn.vti_nc(100, B, D, W, 0.0), wn.vti_nc(100, B, D, W, DH))
        self.assertAlmostEqual(wn.vti_nc(100, B, D, W, DH) / wn.vti_nc(100, B, D, W, 0.0), 0.85 ** -1.5)

    def test_sinkage(self):
        v = wn.vti(60, B, D, W, 0.0)
        self.assertAlmostEqual(v['z_over_d_powered'], 1.64 / (v['ncz'] / v['ssp'] ** 0.19) ** 1.21)
        self.assertAlmostEqual(v['z_over_d_towed'], 2.66 / v['ncz'] ** 1.64 - 0.0063)
        # softer soil, deeper
        self.assertGreater(wn.vti(30, B, D, W)['z_over_d_powered'], v['z_over_d_powered'])


class CrossChecks(unittest.TestCase):
    def test_brixius_by_hand(self):
        # C_n = 60 * 6.894757 * 0.3175 * 0.94 / 8.56 = 14.4235; B_n = C_n / (1 + 3 * 0.33777) = 7.1641 (rigid)
        cn = 60 * 6.894757 * 0.3175 * 0.94 / 8.56
        bn = cn / (1 + 3 * 0.3175 / 0.94)
        self.assertAlmostEqual(wn.brixius_bn(60, B, D, W), bn)
        self.assertAlmostEqual(bn, 7.1641, places=3)
        mr, gt, nt = wn.brixius(0.2, 60, B, D, W)
        self.assertAlmostEqual(mr, 1 / bn + 0.04 + 0.1 / math.sqrt(bn))
        self.assertAlmostEqual(gt, 0.88 * (1 - math.exp(-0.1 * bn)) * (1 - math.exp(-1.5)) + 0.04)
        self.assertAlmostEqual(nt, gt - mr)
        self.assertAlmostEqual(wn.brixius_bn(60, B, D, W, DH), bn * 1.75)
        mr_r, gt_r, _ = wn.brixius(0.2, 60, B, D, W, radial=True)
        self.assertAlmostEqual(mr_r, 0.9 / bn + 0.0325 + 0.1 / math.sqrt(bn))
        self.assertAlmostEqual(gt_r, 0.88 * (1 - math.exp(-0.1 * bn)) * (1 - math.exp(-2.1)))

    def test_wismer_luth_by_hand(self):
        cn = wn.cone_numeric(60, B, D, W)
        tf, gt, pull = wn.wismer_luth(0.2, 60, B, D, W)
        self.assertAlmostEqual(tf, 1.2 / cn + 0.04)
        self.assertAlmostEqual(gt, 0.75 * (1 - math.exp(-0.06 * cn)))
        self.assertAlmostEqual(pull, gt - tf)
        self.assertAlmostEqual(pull, 0.3111, places=3)  # 0.75 (1 - e^-0.8654) - 0.1232

    def test_gross_traction(self):
        v = wn.vti(60, B, D, W)
        gt = wn.vti_gt_over_w(0.2, v['nc'], B, D, v['ssp'])
        self.assertAlmostEqual(gt, wn.vti_dp_over_w(0.2, v['nc'], B, D, v['ssp']) + v['mr_powered'])
        cal = wn.vti_gt_over_w(0.2, v['nc'], B, D, v['ssp'], calibrated=True)
        self.assertAlmostEqual(cal - gt, 0.032 * v['ssp'] ** 0.547 / 0.2 ** 0.777)
        # MAVS's cap: the gross coefficient at most 1
        self.assertAlmostEqual(wn.vti_gt_over_w(0.99, v['nc'], B, D, 1e-4), 1.0)
        self.assertGreater(wn.vti_gt_over_w(0.99, v['nc'], B, D, 1e-4, cap=False), 1.0)


class Band(unittest.TestCase):
    def test_min_max_over_members(self):
        slips = [-0.05, 0.05, 0.2, 0.5]
        band = wn.reference_band(slips, 60, B, D, W)
        self.assertEqual([m[0] for m in wn.BAND_MEMBERS], list(band['members']))
        self.assertEqual([m[2] for m in wn.BAND_MEMBERS], [0.0, 0.15, 0.0, 0.0])
        for i, s in enumerate(slips):
            dps = [c['dp_over_w'][i] for c in band['members'].values()]
            gts = [c['gt_over_w'][i] for c in band['members'].values()]
            defined = [v for v in dps if not math.isnan(v)]
            self.assertEqual(len(defined), 2 if s <= 0 else 4)  # VTI has no value at s <= 0
            self.assertEqual(band['dp_lo'][i], min(defined))
            self.assertEqual(band['dp_hi'][i], max(defined))
            self.assertEqual(band['gt_lo'][i], min(v for v in gts if not math.isnan(v)))
            self.assertLess(band['dp_lo'][i], band['dp_hi'][i])
        v = wn.vti(60, B, D, W, 0.0)
        self.assertEqual(band['members']['VTI, rigid (delta/h 0)']['dp_over_w'][2],
                         wn.vti_dp_over_w(0.2, v['nc'], B, D, v['ssp']))
        towed = [c['towed_dp_over_w'] for c in band['members'].values()]
        self.assertEqual((band['towed_lo'], band['towed_hi']), (min(towed), max(towed)))
        self.assertEqual(band['members']['Wismer-Luth']['towed_dp_over_w'], -wn.wismer_luth(0, 60, B, D, W)[0])
        self.assertEqual(band['members']['VTI, rigid (delta/h 0)']['towed_dp_over_w'], -v['mr_towed'])

    def test_members_follow_the_nominal_deflection(self):
        members = wn.band_members(0.3)
        self.assertEqual(members[1], ('VTI, pneumatic (delta/h 0.3)', 'vti', 0.3))
        with self.assertRaises(ValueError):
            wn.member_curves('wes', [0.2], 60, B, D, W)


if __name__ == '__main__':
    unittest.main()
