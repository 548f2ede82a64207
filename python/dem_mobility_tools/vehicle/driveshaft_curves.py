"""dm-driveshaft-curves: derives the drive-shaft WOT and engine-brake curves (paper fig. 16 quantities) from the engine map
and gearbox of shared/reference/vehicle-data.md section 5 (Chrono HMMWV C++ EngineSimpleMap and
6-speed SimpleMap). Drive-shaft speed = gear ratio x engine speed; drive-shaft torque = engine
torque / ratio. WOT: the envelope (best gear) over the gears whose engine speed lies in the map;
engine brake: the gear a shift schedule holds (highest gear keeping the engine above its idle
range), i.e. the same gear the WOT envelope picks. Prints YAML rows."""
import argparse
import bisect

eng_w = [83.8, 104.7, 125.7, 146.6, 167.6, 188.5, 209.4, 230.4, 251.3]
eng_t = [518, 926, 1216, 1300, 1300, 1227, 1136, 1041, -271]
eb_w = eng_w
eb_t = [0, -20, -20, -30, -30, -30, -40, -50, -70]  # first nine of the ten listed values
ratios = [0.1708, 0.2791, 0.4218, 0.6223, 1.0173, 1.5361]


def interp(xs, ys, x):
    if x <= xs[0]:
        return ys[0]
    if x >= xs[-1]:
        return ys[-1]
    i = bisect.bisect_right(xs, x)
    t = (x - xs[i - 1]) / (xs[i] - xs[i - 1])
    return ys[i - 1] + t * (ys[i] - ys[i - 1])


def best_gear(w_ds):
    best, gear = None, None
    for g, r in enumerate(ratios):
        we = w_ds / r
        if we > eng_w[-2]:  # beyond the governor knee
            continue
        we_c = max(we, eng_w[0])  # clutch slip holds the 800 rpm torque below it
        t = interp(eng_w, eng_t, we_c) / r
        if best is None or t > best:
            best, gear = t, g
    return best, gear


def curves():
    """(WOT rows (speed, torque, gear), engine-brake rows (speed, torque)) at the drive shaft."""
    rows_wot, rows_eb = [], []
    speeds = [0, 14.3, 20, 25, 30, 40, 50, 60, 70, 80, 100, 125, 150, 175, 200, 225, 250, 275, 300, 325, 350, 375]
    for w in speeds:
        t, g = best_gear(w)
        if t is None:
            continue
        r = ratios[g]
        eb = interp(eb_w, eb_t, max(w / r, eb_w[0])) / r
        rows_wot.append((w, t, g + 1))
        rows_eb.append((w, eb))
    # governor: past the top gear's knee the torque falls to the cut value
    w_cut = eng_w[-1] * ratios[-1]
    rows_wot.append((round(w_cut, 1), eng_t[-1] / ratios[-1], 6))
    # past the cut the governor's torque is the lower bound too
    rows_eb.append((round(w_cut, 1), min(interp(eb_w, eb_t, eng_w[-1]), eng_t[-1]) / ratios[-1]))
    return rows_wot, rows_eb


def main(argv=None):
    argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter).parse_args(argv)
    rows_wot, rows_eb = curves()
    print("wot_torque:  # [drive-shaft speed rad/s, torque N m], gear in comment")
    for w, t, g in rows_wot:
        print(f"  - [{w:g}, {t:.0f}]  # gear {g}")
    print("engine_brake_torque:")
    for w, t in rows_eb:
        print(f"  - [{w:g}, {t:.0f}]")
    return 0


if __name__ == '__main__':
    main()
