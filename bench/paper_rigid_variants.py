#!/usr/bin/env python3
"""Rigid variants of the `paper` reading that are not options of the twin (docs/model.md,
"Open-item choices of the `paper` reading" and "Against the paper").

The pack's spring drag acts on the connecting shaft instead of the output, and after the drive
is cut the input side (J_r + J_c + reflected motor inertia J_m) is a free inertia braked by that
drag while it carries the connecting shaft. Everything else is the paper reading: quasi-static
pressing force from the load (T_all = 59.0 N·m with mu_s while the load face is engaged,
8.43 N·m spring only), engagement when the output runs ahead of the input side, far face of
the output ramp a plain stop after the release. Fixed-step (2 us) integration of
constant-torque phases; Table 2 values only. Prints the continuous-closing period, and the
forward and reverse braking time and angle for several J_m.

    python3 bench/paper_rigid_variants.py
"""

JS, JC, JR = 0.15, 1.4e-3, 1.3e-3  # Table 2 (kg m^2)
M = 20.3  # load torque (N m)
TS, TA = 8.43, 59.0  # pack capacity, spring only / spring + load, mu_s (N m)
W0 = 13.78  # rad/s
B = 2 * 0.2e-3 / (0.02 * 0.5**0.5)  # backlash 2 g_p1 / (r cos theta)


def closing(kind, jm, drag_on_output, dt=2e-6):
    """Continuous closing ('cc': period) or forward load ('fwd': braking time and angle)."""
    ji = JR + JC + jm
    ths = thi = 0.0
    ws = 0.0 if kind == "cc" else W0
    wi = W0
    t_end, rel = (3.0, 1e9) if kind == "cc" else (1.0, 0.2)
    t, ups, last, stuck, stop_t, ang0 = 0.0, [], None, False, None, None
    while t < t_end:
        drive = t < rel
        if not drive and ang0 is None:
            ang0 = ths
        eng = ths - thi >= 0
        if stuck:
            a_s = 0.0
        elif eng:
            a_s = (M - TA) / (JS + JC)
        else:
            a_s = (M - (TS if drag_on_output else 0.0)) / JS
        a_i = 0.0 if (drive or eng or drag_on_output) else -TS / ji
        ws += a_s * dt
        wi = max(0.0, wi + a_i * dt) if not drive else wi
        if not stuck and not drive and eng and ws <= 0:
            ws, stuck, stop_t = 0.0, True, t
        ths += ws * dt
        thi += wi * dt
        t += dt
        cur = TA if eng else TS
        if kind == "cc" and t > 1.2:
            if last is not None and last < 30 <= cur:
                ups.append(t)
            last = cur
    if kind == "cc":
        return (ups[-1] - ups[0]) / (len(ups) - 1) if len(ups) > 1 else None
    return (stop_t - rel if stop_t else None), ths - ang0


def reverse(jm, dt=2e-6):
    """Reverse load: lag (load face re-engaged), braking time, net angle."""
    ji = JR + JC + jm
    ths = thi = 0.0
    ws = wi = -W0
    t, lag, stop = 0.2, None, None
    while t < 1.0 and stop is None:
        d = ths - thi
        if d >= 0 and ws > 0:  # load face: output, shaft and input side braked by the pack
            lag = t - 0.2 if lag is None else lag
            ws += (M - TA) / (JS + ji) * dt
            wi = ws
            if ws <= 0:
                ws = wi = 0.0
                stop = t - 0.2
        elif d <= -B and ws < 0:  # far face: the output pushes the drag-held input side
            ws += (M + TS) / (JS + ji) * dt
            wi = ws
            if ws >= 0:
                ws = wi = 0.0
        else:
            ws += M / JS * dt
            if wi < 0:
                wi = min(0.0, wi + TS / ji * dt)
        ths += ws * dt
        thi += wi * dt
        t += dt
    return lag, stop, abs(ths)


if __name__ == "__main__":
    print("continuous closing period, drag on output (the reading): %.3f s" % closing("cc", 0, True))
    print("continuous closing period, drag on connecting shaft:     %.3f s" % closing("cc", 0, False))
    for jm in (0.0, 0.01, 0.02, 0.03, 0.05):
        ft, fa = closing("fwd", jm, False)
        rl, rt, ra = reverse(jm)
        print(
            "J_m = %.2f: forward %.3f s / %.3f rad; reverse lag %.3f s, %.3f s / %.3f rad"
            % (jm, ft, fa, rl, rt, ra)
        )
