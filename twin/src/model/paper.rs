//! The `paper` reading: the paper's Simulink platform as MODEL.md's quasi-static reading
//! describes it. It reproduces the paper's torque levels and its continuous-closing cycle; it
//! is not coherent mechanics (docs/model.md, "Two readings").
//!
//! - The pressing force is quasi-static: the spring preload, plus the ramp force of the *load*
//!   torque `|M|·tanθ/r` while the load-holding ramp face is engaged. The face is engaged when
//!   the output has run ahead of the input in the load direction (`θs − θin ≥ 0`).
//! - The Table 1 braking torque, with μ_s both stuck and slipping, acts on the output inertia
//!   J_s through the shared stick/slip machine.
//! - The input is an ideal speed reference while the drive is on and stops when it is cut.
//!   Driving against the load (opening) the drive carries the output at the reference speed and
//!   its input ramp keeps the pack unlocked (spring drag only); driving along the load
//!   (closing) the drive only sets the reference the output is compared with (the output may
//!   lag it by far more than the clearance, as the paper's cycle requires).
//! - A drive along the load under a torque limit (the functional test's push) pushes with its
//!   limit `T`: the input turns with the output, the pack holds `M + T`, pressed by
//!   `F_s + (|M| − T)·tanθ/r` (docs/model.md, "The `paper` reading").
//! - An output that meets the engagement point at the input's speed with the drive on along
//!   the load *tracks* the input (a Filippov sliding mode of the switch): it runs at the
//!   reference speed with the pack holding exactly the load. Without this the switch chatters
//!   and the state at release depends on the step size.
//! - After the drive is cut, the connecting shaft (the input side) is held by the spring-applied
//!   drag, and the output ramp's far face is a plain stop: an output running against the load
//!   by more than the ramp backlash `2·g_p1/(r cosθ)` pushes it along (MODEL.md, "Braking
//!   cases": this is what produces the reverse-load lag). `open.paper_backlash_rad` overrides
//!   the derived backlash, `open.paper_far_face_stop` removes the stop and
//!   `open.paper_sliding_mu_static = false` uses μ_d while slipping (sensitivity only).
//! - The reading is rigid and has no axial state. Its samples report the pressing force the
//!   pack torque corresponds to (while tracking, the Filippov mean that holds exactly the load)
//!   and the quasi-static axial positions it implies through the pack and ball contacts
//!   (Herbert–McWhannell, Table 2 k), so the continuous-closing axial travel is the pack's
//!   deflection range. Why several of the paper's figures are out of reach of any rigid
//!   choice: docs/model.md, "Against the paper".

use super::{at, put, smooth_sign, Drive, ModelConfig, Sample, TwinModel};
use crate::fault::PhysicsFaults;
use crate::friction::{self, FrictionMode};
use crate::pack::{self, PackCapacity};
use crate::solver::OdeSystem;
use crate::spring::spring_force_n;
use noback::mechanism::GRAVITY_M_S2;

/// Output angle.
pub const THETA_S: usize = 0;
/// Input (reference) angle.
pub const THETA_IN: usize = 2;
/// Number of states: θs, ωs, θin.
pub const N: usize = 3;

/// The paper-reading model.
#[derive(Clone, Debug)]
pub struct Paper {
    cfg: ModelConfig,
    faults: PhysicsFaults,
    mode: FrictionMode,
    drive: Drive,
    driven: bool,
    pushing: bool,
    tracking: bool,
}

impl Drive {
    /// Torque of a push along the load under a torque limit (N·m, ≥ 0); `None` when the drive is
    /// off, runs against the load or holds a speed reference.
    fn limited_push_nm(&self, load_sign: f64, motor_nm: f64) -> Option<f64> {
        let along = self.on && self.speed_ref_rad_s * load_sign > 0.0;
        self.torque_limit_nm
            .filter(|_| along)
            .map(|l| l.clamp(0.0, motor_nm))
    }
}

struct Eval {
    dy: [f64; N],
    /// Pressing force the pack torque corresponds to (N): the full quasi-static force while
    /// engaged, the spring alone while not, and while tracking the Filippov mean that makes the
    /// pack torque equal to the load.
    pressing_n: f64,
    /// Fraction of the load's ramp force the load face carries (1 engaged, 0 not, between
    /// while tracking).
    engaged: f64,
    /// Torque the load face carries (N·m): the load less a limited push.
    face_nm: f64,
    /// Pressing force the capacities are computed from (N): spring, drag and, while engaged or
    /// tracking, the whole ramp force.
    capacity_pressing_n: f64,
    pack_torque_nm: f64,
    required_nm: f64,
    cap: PackCapacity,
    drive_nm: f64,
}

impl Paper {
    /// Build the model.
    pub fn new(cfg: ModelConfig) -> Self {
        let mut p = Paper {
            cfg,
            faults: PhysicsFaults::default(),
            mode: FrictionMode::Stuck,
            drive: cfg.drive,
            driven: false,
            pushing: false,
            tracking: false,
        };
        p.driven = p.drives_output();
        p
    }

    fn load_sign(&self) -> f64 {
        super::load_sign(self.cfg.load_torque_nm)
    }

    /// The drive carries the output when it runs against the load (opening).
    fn drives_output(&self) -> bool {
        self.drive.on && self.drive.speed_ref_rad_s * self.load_sign() < 0.0
    }

    /// Angular backlash of the output ramp (rad): `open.paper_backlash_rad` if set, otherwise
    /// derived from Table 2 as `2·g_p1/(r·cosθ)` (0.028 rad: the clearance g_p1 on each face).
    pub fn backlash_rad(&self) -> f64 {
        if self.cfg.open.paper_backlash_rad > 0.0 {
            return self.cfg.open.paper_backlash_rad;
        }
        let m = &self.cfg.mechanism;
        2.0 * m.socket_clearance_m / (m.socket_radius_m * m.socket_chamfer_rad.cos())
    }

    /// Current friction mode.
    pub fn mode(&self) -> FrictionMode {
        self.mode
    }

    /// The limited push's torque (N·m, ≥ 0), if the drive is pushing along the load.
    fn push_nm(&self) -> Option<f64> {
        self.drive
            .limited_push_nm(self.load_sign(), self.cfg.drive_torque_limit_nm())
    }

    fn eval(&self, y: &[f64]) -> Eval {
        let m = &self.cfg.mechanism;
        let push = self.push_nm();
        // The push adds to what the pack holds and takes its share off the load face.
        let load = self.cfg.load_torque_nm + push.unwrap_or(0.0) * self.load_sign();
        let face_nm = (self.cfg.load_torque_nm.abs() - push.unwrap_or(0.0)).max(0.0);
        let w = at(y, THETA_S + 1);
        let delta = (at(y, THETA_S) - at(y, THETA_IN)) * self.load_sign();
        let engaged = !self.driven && (self.tracking || push.is_some() || delta >= 0.0);
        let spring = spring_force_n(
            m,
            m.pack_clearance_m + self.faults.extra_pack_clearance_m,
            self.faults.spring_scale,
        );
        let ramp = if engaged {
            face_nm * m.ramp_factor_per_m() * (1.0 - self.faults.ramp_jam)
        } else {
            0.0
        };
        let pressing_n = spring + self.faults.drag_force_n + ramp;
        let cap = pack::capacity(
            m,
            pressing_n,
            self.faults.mu_scale,
            self.cfg.open.paper_sliding_mu_static,
        );
        let bearing = m.mu_dynamic
            * m.output_shaft_mass_kg
            * GRAVITY_M_S2
            * m.output_friction_radius_m
            * smooth_sign(w, self.cfg.open.bearing_smoothing_rad_s);
        let stuck = self.mode == FrictionMode::Stuck && !self.driven;
        let required_nm = load - if stuck { 0.0 } else { bearing };
        let mut dy = [0.0; N];
        let base_n = spring + self.faults.drag_force_n;
        let (pack_torque_nm, drive_nm) = if self.tracking {
            ((-required_nm).clamp(-cap.static_nm, cap.static_nm), 0.0)
        } else if self.driven {
            // Kinematic: the drive supplies whatever holds the reference speed.
            let pack = if w > 0.0 {
                -cap.sliding_nm
            } else if w < 0.0 {
                cap.sliding_nm
            } else {
                0.0
            };
            (pack, -(required_nm + pack))
        } else {
            let drive = push.map_or(0.0, |t| t * self.load_sign());
            (friction::torque_nm(self.mode, required_nm, cap), drive)
        };
        // While tracking the switch is visited in a Filippov mean: report the pressing force
        // (and the load-face share) that gives exactly the pack torque being applied.
        let engaged_share = if self.tracking && ramp > 0.0 && pressing_n > 0.0 {
            let per_n = cap.sliding_nm / pressing_n;
            if per_n > 0.0 {
                ((pack_torque_nm.abs() / per_n - base_n) / ramp).clamp(0.0, 1.0)
            } else {
                1.0
            }
        } else if engaged {
            1.0
        } else {
            0.0
        };
        let capacity_pressing_n = pressing_n;
        let pressing_n = base_n + engaged_share * ramp;
        dy[THETA_S] = w;
        dy[THETA_S + 1] = if self.driven
            || (self.tracking && required_nm.abs() <= cap.static_nm)
            || (stuck && required_nm.abs() <= cap.static_nm)
        {
            0.0
        } else {
            (required_nm + pack_torque_nm) / m.output_inertia_kg_m2
        };
        dy[THETA_IN] = if push.is_some() {
            w
        } else if self.drive.on {
            self.drive.speed_ref_rad_s
        } else if self.pushing {
            w
        } else {
            0.0
        };
        Eval {
            dy,
            pressing_n,
            engaged: engaged_share,
            face_nm,
            capacity_pressing_n,
            pack_torque_nm,
            required_nm,
            cap,
            drive_nm,
        }
    }

    fn update_pushing(&mut self, y: &mut [f64]) {
        let ls = self.load_sign();
        let w = at(y, THETA_S + 1) * ls;
        let delta = (at(y, THETA_S) - at(y, THETA_IN)) * ls;
        if self.drive.on {
            self.pushing = false;
        } else if self.pushing {
            if w >= 0.0 {
                self.pushing = false;
            }
        } else if self.cfg.open.paper_far_face_stop
            && delta <= -self.backlash_rad() + 1e-12
            && w < 0.0
        {
            self.pushing = true;
            put(y, THETA_IN, at(y, THETA_S) + self.backlash_rad() * ls);
        }
    }

    /// Enter or leave the tracking sliding mode (see the module doc).
    fn update_tracking(&mut self, y: &mut [f64]) {
        let along = self.drive.on && !self.driven && self.push_nm().is_none();
        if !along {
            self.tracking = false;
            return;
        }
        let w_ref = self.drive.speed_ref_rad_s;
        let w = at(y, THETA_S + 1);
        let delta = (at(y, THETA_S) - at(y, THETA_IN)) * self.load_sign();
        let was = self.tracking;
        self.tracking = true;
        let e = self.eval(y);
        let spring_only = pack::capacity(
            &self.cfg.mechanism,
            e.capacity_pressing_n
                - self.cfg.load_torque_nm.abs() * self.cfg.mechanism.ramp_factor_per_m(),
            self.faults.mu_scale,
            self.cfg.open.paper_sliding_mu_static,
        );
        // Both sides of the switch push towards it: disengaged the output would gain on the
        // input, engaged it would fall back.
        let holds = e.required_nm.abs() <= e.cap.static_nm
            && e.required_nm * self.load_sign() > spring_only.sliding_nm;
        let on_surface = (w - w_ref).abs() <= 1e-6 * w_ref.abs().max(1.0) && delta.abs() <= 1e-9;
        self.tracking = holds && (was || on_surface);
        if self.tracking {
            put(y, THETA_S + 1, w_ref);
            self.mode = FrictionMode::Forward;
        }
    }

    fn settle_mode(&mut self, y: &mut [f64]) {
        if self.tracking {
            return;
        }
        if self.driven {
            self.mode = FrictionMode::Forward;
            put(y, THETA_S + 1, self.drive.speed_ref_rad_s);
            return;
        }
        self.mode = FrictionMode::Stuck;
        let e = self.eval(y);
        self.mode = friction::settle(at(y, THETA_S + 1), e.required_nm, e.cap);
        if self.mode == FrictionMode::Stuck {
            put(y, THETA_S + 1, 0.0);
        }
    }
}

impl OdeSystem for Paper {
    fn dim(&self) -> usize {
        N
    }

    fn scales(&self) -> Vec<f64> {
        vec![1e-2, 1.0, 1e-2]
    }

    fn rhs(&self, _t: f64, y: &[f64], dy: &mut [f64]) {
        dy.copy_from_slice(&self.eval(y).dy);
    }

    fn event_count(&self) -> usize {
        3
    }

    fn events(&self, _t: f64, y: &[f64], g: &mut [f64]) {
        let e = self.eval(y);
        put(
            g,
            0,
            if self.tracking {
                1.0
            } else {
                (at(y, THETA_S) - at(y, THETA_IN)) * self.load_sign()
            },
        );
        put(
            g,
            1,
            if self.tracking {
                e.cap.static_nm - e.required_nm.abs()
            } else if self.driven {
                1.0
            } else {
                friction::event_value(self.mode, at(y, THETA_S + 1), e.required_nm, e.cap)
            },
        );
        let far = if self.drive.on || !self.cfg.open.paper_far_face_stop {
            1.0
        } else if self.pushing {
            // Stop pushing when the output turns back towards the load direction.
            -at(y, THETA_S + 1) * self.load_sign()
        } else {
            (at(y, THETA_S) - at(y, THETA_IN)) * self.load_sign() + self.backlash_rad()
        };
        put(g, 2, far);
    }

    fn on_event(&mut self, _t: f64, y: &mut [f64], _fired: &[usize]) {
        self.update_pushing(y);
        self.update_tracking(y);
        self.settle_mode(y);
    }
}

impl TwinModel for Paper {
    fn initial_state(&self) -> Vec<f64> {
        vec![0.0, self.cfg.output_initial_speed_rad_s, 0.0]
    }

    fn set_drive(&mut self, drive: Drive, y: &mut [f64]) {
        self.drive = drive;
        self.driven = self.drives_output();
        self.tracking = false;
        self.update_pushing(y);
        self.update_tracking(y);
        self.settle_mode(y);
    }

    fn set_faults(&mut self, faults: PhysicsFaults, y: &mut [f64]) {
        self.faults = faults;
        self.update_tracking(y);
        self.settle_mode(y);
    }

    fn sample(&self, t: f64, y: &[f64]) -> Sample {
        let e = self.eval(y);
        let m = &self.cfg.mechanism;
        let per_ball =
            e.engaged * e.face_nm / (3.0 * m.socket_radius_m * m.socket_chamfer_rad.cos());
        // Quasi-static axial positions (docs/model.md, "The `paper` reading"): the big shaft
        // sits on the pack, deflected by the pressing force through the pack's Herbert–McWhannell
        // contact (`x = g_p2 + (F_p/k)^(2/3)`); the output balls sit on the output shaft's face,
        // pressed into it by the axial component of their ramp force.
        let deflection = |f: f64| (f.max(0.0) / m.contact_stiffness).powf(2.0 / 3.0);
        let shaft_axial_m =
            m.pack_clearance_m + self.faults.extra_pack_clearance_m + deflection(e.pressing_n);
        let ball_axial_m = -deflection(per_ball * m.socket_chamfer_rad.sin());
        Sample {
            t_s: t,
            output_angle_rad: at(y, THETA_S),
            output_speed_rad_s: at(y, THETA_S + 1),
            input_angle_rad: at(y, THETA_IN),
            input_speed_rad_s: e.dy[THETA_IN],
            drive_torque_nm: e.drive_nm,
            drive_on: self.drive.on,
            pressing_force_n: e.pressing_n,
            braking_torque_nm: e.pack_torque_nm.abs(),
            brake_state: if self.driven {
                0
            } else {
                self.mode.brake_state()
            },
            contact_force_n: per_ball,
            input_contact_force_n: 0.0,
            ball_axial_m,
            shaft_axial_m,
        }
    }

    fn energy_j(&self, y: &[f64]) -> f64 {
        0.5 * self.cfg.mechanism.output_inertia_kg_m2 * at(y, THETA_S + 1).powi(2)
            - self.cfg.load_torque_nm * at(y, THETA_S)
    }
}
