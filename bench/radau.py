#!/usr/bin/env python3
"""Independent solve of the twin's `physical` reading with scipy's solve_ivp(method="Radau").

The same equations as twin/src/model/physical.rs (docs/model.md), written again from the
documentation: 14 states, eight Herbert-McWhannell contacts, the wave spring, smoothed bearing
and guide friction, ball friction, the P speed servo, and the pack's stick/slip machine with
located events (contact onset records the approach speed; slip->stick at zero speed; breakaway).
Used by `cargo run --release -p noback-twin --example bench` to compare speed at matched
tolerance. Prints one JSON object.

usage: radau.py SCENE [--tolerance TOL] [--record-all]
"""
import json
import math
import sys
import time

import numpy as np
from scipy.integrate import solve_ivp

# Table 2 (noback::mechanism::TABLE2) and the twin's defaults (docs/model.md).
M_S, M_R, M_B, M_C = 0.173, 0.206, 0.003, 0.285
J_S, J_R, J_C, J_B = 0.15, 1.3e-3, 1.4e-3, 1.2e-4
LOAD, K_T, K, X0 = 20.3, 9.4e4, 2.53e9, 2.3e-3
R, R_MS, R_MD, R_MR = 0.02, 0.012, 0.01, 0.01
R1, R2, GP1, GP2 = 0.0285, 0.0375, 0.2e-3, 0.5e-3
THETA, NF, MU_S, MU_D, E = math.pi / 4, 3, 0.3, 0.17, 0.5
G = 9.81
TOUCH_EVENT_M = 1e-15
RECORD_ALL = False  # set from the command line
FLOOR = 0.01          # approach-speed floor (m/s)
KP = 50.0             # servo gain (N m s/rad)
T_LIM = 25.0 * 0.06 * 30 * 0.9
W_SM, V_SM = 0.01, 1e-4
R_EFF = 2 * math.pi * (R2**3 - R1**3) / (3 * math.pi * (R2**2 - R1**2))
PER_N = (2 * NF - 1) * R_EFF  # pack torque per newton per unit mu
CE = 6 * (1 - E) / ((2 * E - 1) ** 2 + 3)

TR, XI, XM, TC, XB, XO, TS = 0, 2, 4, 6, 8, 10, 12
N = 14
RC, S = R * math.cos(THETA), math.sin(THETA)
G2, G4 = GP1 - S * GP2, GP1 + S * GP2
# (terms, gap, multiplicity)
CONTACTS = [
    ([(XO, -1.0)], 0.0, 3.0),
    ([(TS, RC), (TC, -RC), (XO, S), (XB, -S)], G2, 3.0),
    ([(TS, -RC), (TC, RC), (XO, S), (XB, -S)], G2, 3.0),
    ([(XI, 1.0)], 0.0, 3.0),
    ([(TR, RC), (TC, -RC), (XM, S), (XI, -S)], G4, 3.0),
    ([(TR, -RC), (TC, RC), (XM, S), (XI, -S)], G4, 3.0),
    ([(XB, 1.0), (XM, -1.0)], 0.0, 1.0),
    ([(XB, 1.0)], GP2, 1.0),
]
PACK = 7
FREE, FWD, STUCK, BWD = 0, 1, 2, 3


class Model:
    def __init__(self, drive_on, w_ref, w0, w_out0):
        self.drive_on, self.w_ref = drive_on, w_ref
        self.approach = [FLOOR] * len(CONTACTS)
        self.mode = STUCK
        self.y0 = np.zeros(N)
        self.y0[TR + 1] = self.y0[TC + 1] = w0
        self.y0[TS + 1] = w_out0
        self.y0[XB] = GP2
        self.y0[XM] = GP2
        self.y0[TS] = GP1 / RC
        if drive_on:
            self.y0[TR] = math.copysign(1.0, w_ref) * GP1 / RC

    def pen(self, c, y):
        terms, gap, _ = c
        d = -gap + sum(k * y[i] for i, k in terms)
        v = sum(k * y[i + 1] for i, k in terms)
        return d, v

    def eval(self, y):
        q = np.zeros(N)
        f = [0.0] * len(CONTACTS)
        for k, c in enumerate(CONTACTS):
            d, v = self.pen(c, y)
            if d > 0:
                fn = K * d * math.sqrt(d) * (1 + CE * v / self.approach[k])
                f[k] = max(fn, 0.0)
            for i, coeff in c[0]:
                q[i] -= c[2] * f[k] * coeff
        fp = f[PACK]
        q[TS] -= MU_D * M_S * G * R_MS * math.tanh(y[TS + 1] / W_SM)
        q[TR] -= MU_D * M_R * G * R_MR * math.tanh(y[TR + 1] / W_SM)
        conn = MU_D * M_C * G * R_MD * math.tanh(y[TC + 1] / W_SM)
        q[XB] -= MU_D * M_C * G * math.tanh(y[XB + 1] / V_SM)
        q[XM] -= MU_D * M_C * G * math.tanh(y[XM + 1] / V_SM)
        c = math.cos(THETA)
        q[XO] -= 3 * MU_D * abs(f[0] - f[1] - f[2]) * c * math.tanh(y[XO + 1] / V_SM)
        q[XI] -= 3 * MU_D * abs(f[3] - f[4] - f[5]) * c * math.tanh(y[XI + 1] / V_SM)
        q[XB] += max(K_T * (X0 - y[XB]), 0.0)
        q[TS] += LOAD
        drive = 0.0
        if self.drive_on:
            drive = min(max(KP * (self.w_ref - y[TR + 1]), -T_LIM), T_LIM)
        q[TR] += drive
        cap_s, cap_d = MU_S * PER_N * fp, MU_D * PER_N * fp
        stuck = self.mode == STUCK
        req = q[TC] - (0.0 if stuck else conn)
        if self.mode == FREE:
            tp = 0.0
        elif self.mode == FWD:
            tp = -cap_d
        elif self.mode == BWD:
            tp = cap_d
        else:
            tp = min(max(-req, -cap_s), cap_s)
        q[TC] = req + tp
        dy = np.zeros(N)
        mass = {TR: J_R + 3 * J_B, XI: 3 * M_B, XM: M_C, TC: J_C, XB: M_C, XO: 3 * M_B, TS: J_S + 3 * J_B}
        for i, m in mass.items():
            dy[i] = y[i + 1]
            dy[i + 1] = q[i] / m
        if stuck and abs(req) <= cap_s:
            dy[TC] = dy[TC + 1] = 0.0
        return dy, fp, tp, req, cap_s, cap_d

    def rhs(self, t, y):
        return self.eval(y)[0]

    def event_values(self, y):
        # As the twin: a contact's event fires at 1e-15 m, not at 0 (a contact seated at zero
        # penetration within rounding would fire at every step).
        g = [self.pen(c, y)[0] - TOUCH_EVENT_M for c in CONTACTS]
        _, fp, _, req, cap_s, cap_d = self.eval(y)
        if self.mode in (FWD, BWD):
            g.append(y[TC + 1])
        elif self.mode == STUCK:
            g.append(cap_s - abs(req))
        else:
            g.append(1.0 if cap_s > 0 else -1.0)
        return g

    def settle(self, y):
        self.mode = STUCK
        _, fp, _, req, cap_s, cap_d = self.eval(y)
        w = y[TC + 1]
        if cap_s <= 0 and cap_d <= 0:
            self.mode = FREE
        elif w > 1e-6:
            self.mode = FWD
        elif w < -1e-6:
            self.mode = BWD
        elif abs(req) <= cap_s:
            self.mode = STUCK
            y[TC + 1] = 0.0
        else:
            self.mode = FWD if req > 0 else BWD

    def on_event(self, y, fired):
        # As the twin: only the contacts whose event fired re-record their approach speed
        # (`--record-all`: every touching contact, the script's former rule).
        for k, c in enumerate(CONTACTS):
            if not RECORD_ALL and k not in fired:
                continue
            d, v = self.pen(c, y)
            if abs(d) < 1e-12 or d > 0:
                self.approach[k] = max(abs(v), FLOOR) if (d >= -1e-12 and v > 0) else FLOOR
        self.settle(y)


def run(scene, tol):
    w = 13.78
    if scene == "reverse_load":
        m, release, dur = Model(True, -w, -w, -w), 0.2, 1.0
    elif scene == "forward_load":
        m, release, dur = Model(True, w, w, w), 0.2, 1.0
    elif scene == "continuous_closing":
        m, release, dur = Model(True, w, w, 0.0), None, 3.0
    elif scene == "hold":
        m, release, dur = Model(False, 0.0, 0.0, 0.0), None, 0.5
    else:
        raise SystemExit(f"unknown scene {scene}")
    y = m.y0.copy()
    m.settle(y)
    t = 0.0
    breaks = ([release] if release else []) + [dur]
    nfev = nevents = 0
    grid_t, grid_w, grid_a = [], [], []
    next_sample = 0.0
    start = time.perf_counter()
    for b in breaks:
        while t < b - 1e-12:
            ne = len(CONTACTS) + 1
            g0 = m.event_values(y)

            def make(i):
                # Only a strict sign change from a non-zero start value is an event (as in the
                # twin); a function that starts at (rounding) zero is ignored until the next
                # restart.
                sign0 = 1.0 if g0[i] > 1e-15 else (-1.0 if g0[i] < -1e-15 else 0.0)

                def ev(tt, yy):
                    if sign0 == 0.0:
                        return 1.0
                    return m.event_values(yy)[i]
                ev.terminal = True
                return ev

            events = [make(i) for i in range(ne)]
            sol = solve_ivp(m.rhs, (t, b), y, method="Radau", rtol=tol,
                            atol=tol * np.array([1e-2, 1, 1e-5, 0.1] * 1 + [1e-5, 0.1, 1e-2, 1, 1e-5, 0.1, 1e-5, 0.1, 1e-2, 1]),
                            events=events, dense_output=True, max_step=1e-3)
            nfev += sol.nfev
            t_end = sol.t[-1]
            while next_sample <= t_end + 1e-12:
                ys = sol.sol(next_sample)
                grid_t.append(next_sample)
                grid_w.append(ys[TS + 1])
                grid_a.append(ys[TS])
                next_sample += 1e-4
            y = sol.y[:, -1].copy()
            fired = {i for i, te in enumerate(sol.t_events or []) if len(te)}
            stalled = t_end - t < 1e-12
            t = t_end
            if sol.status == 1 and stalled:
                # An event at the restart point (rounding): step past it without events.
                nudge = solve_ivp(m.rhs, (t, min(t + 1e-9, b)), y, method="Radau", rtol=tol)
                nfev += nudge.nfev
                y = nudge.y[:, -1].copy()
                t = nudge.t[-1]
                m.on_event(y, fired)
            elif sol.status == 1:
                nevents += 1
                # step just past the root so the sign has changed
                m.on_event(y, fired)
            elif sol.status < 0:
                raise SystemExit(sol.message)
        if release is not None and abs(b - release) < 1e-12:
            m.drive_on = False
            m.settle(y)
    wall = time.perf_counter() - start
    out = {"scene": scene, "tolerance": tol, "wall_s": wall, "rhs_evals": nfev, "events": nevents}
    if release is not None or scene == "hold":
        r = release or 0.0
        w_arr, a_arr, t_arr = np.array(grid_w), np.array(grid_a), np.array(grid_t)
        after = t_arr >= r - 1e-12
        moving = np.where(np.abs(w_arr[after]) >= 0.05)[0]
        if len(moving) and moving[-1] + 1 < after.sum():
            i = moving[-1] + 1
            out["braking_time_s"] = float(t_arr[after][i] - r)
            out["braking_angle_rad"] = float(abs(a_arr[after][i] - a_arr[after][0]))
    print(json.dumps(out))


if __name__ == "__main__":
    args = sys.argv[1:]
    RECORD_ALL = "--record-all" in args
    tol = 1e-5
    if "--tolerance" in args:
        tol = float(args[args.index("--tolerance") + 1])
    run(args[0], tol)
