//! The `physical` reading: every body and degree of freedom of paper §2.2 with
//! Herbert–McWhannell contacts, the wave spring and the stick/slip pack.
//!
//! Bodies and state (positions at even, speeds at odd indices; positive rotation = load
//! direction, positive axial = towards the pack):
//! input shaft rotation θr (the input-end balls turn with it, as the paper's Eq. 24 has them:
//! `J_b·θ̈_r`); input-end balls axial xi (three balls lumped); small connecting shaft axial xm;
//! connecting shaft rotation θc (small and big shafts are splined: one rotation); big connecting
//! shaft axial xb; output-end balls axial xo; output shaft rotation θs (the output-end balls turn
//! with it, paper Eq. 9: `J_b·θ̈_s`). Input and output shafts are held axially by bearings.
//!
//! Each ball is carried in rotation by its shaft's pocket and rests axially on that shaft's face
//! (contacts c1, c3: axial stops); it meets the connecting shaft's V-shaped socket with a plus
//! and a minus face (c2±, c4±). Carrying the ball in rotation removes the neutral direction a
//! ball between two parallel ramp faces would have (it would roll away along them). The
//! penetration of a face is linear in the coordinates (`δ = ±r cosθ·Δθ + sinθ·Δx − g_p1`,
//! MODEL.md), and its force acts along the gradient, so contact forces are conservative up to
//! their damping.
//! The output balls push the big shaft towards the pack; the input balls push the small shaft,
//! which pushes the big shaft away from the pack (unlocking); the wave spring pushes the big
//! shaft onto the pack. The pack brakes the connecting shaft against the housing.

use super::{at, put, smooth_sign, Drive, ModelConfig, Sample, TwinModel};
use crate::contact::ContactLaw;
use crate::fault::PhysicsFaults;
use crate::friction::{self, FrictionMode};
use crate::pack::{self, PackCapacity};
use crate::solver::OdeSystem;
use crate::spring::spring_force_n;
use noback::mechanism::GRAVITY_M_S2;

/// Input shaft (and input-end balls) angle.
pub const THETA_R: usize = 0;
/// Input-end balls, axial.
pub const X_I: usize = 2;
/// Small connecting shaft, axial.
pub const X_M: usize = 4;
/// Connecting shaft, rotation.
pub const THETA_C: usize = 6;
/// Big connecting shaft, axial.
pub const X_B: usize = 8;
/// Output-end balls, axial.
pub const X_O: usize = 10;
/// Output shaft (and output-end balls) angle.
pub const THETA_S: usize = 12;
/// Number of states.
pub const N: usize = 14;

/// Index of the pack contact in [`Physical::contacts`].
const PACK: usize = 7;
/// Number of contacts.
const NC: usize = 8;
/// A contact's event fires at this penetration, not at 0: a contact set exactly touching
/// (δ = 0, rounding noise of ~1e-19 m) would otherwise fire at every step (seed 7, run 9297).
const TOUCH_EVENT_M: f64 = 1e-15;

/// One contact: penetration `δ = Σ coeff·q − gap`, acting `multiplicity` times (three balls).
#[derive(Clone, Debug, PartialEq)]
pub struct ContactDef {
    /// Name for diagnostics.
    pub name: &'static str,
    /// `(position index, coefficient)` terms.
    pub terms: Vec<(usize, f64)>,
    /// Clearance (m).
    pub gap_m: f64,
    /// How many identical contacts act (3 for the balls).
    pub multiplicity: f64,
}

impl ContactDef {
    fn penetration(&self, y: &[f64]) -> (f64, f64) {
        let mut d = -self.gap_m;
        let mut v = 0.0;
        for &(i, c) in &self.terms {
            d += c * at(y, i);
            v += c * at(y, i + 1);
        }
        (d, v)
    }
}

/// The physical model.
#[derive(Clone, Debug)]
pub struct Physical {
    cfg: ModelConfig,
    faults: PhysicsFaults,
    /// The eight contacts: c1, c2± (output end), c3, c4± (input end), shafts, pack.
    pub contacts: Vec<ContactDef>,
    approach: Vec<f64>,
    mode: FrictionMode,
    drive: Drive,
    law: ContactLaw,
    conservative: bool,
}

/// Forces evaluated at one state.
struct Eval {
    dy: [f64; N],
    contact_n: [f64; NC],
    pressing_n: f64,
    pack_torque_nm: f64,
    required_nm: f64,
    cap: PackCapacity,
    drive_nm: f64,
}

impl Physical {
    /// Build the model with the load path seated (load faces just touching).
    pub fn new(cfg: ModelConfig) -> Self {
        let m = cfg.mechanism;
        let rc = m.socket_radius_m * m.socket_chamfer_rad.cos();
        let s = m.socket_chamfer_rad.sin();
        let g = m.socket_clearance_m;
        let c = |name, terms: Vec<(usize, f64)>, gap_m, multiplicity| ContactDef {
            name,
            terms,
            gap_m,
            multiplicity,
        };
        // Axial seat of a ball on its own shaft's face: no clearance (the ball rests there;
        // the whole clearance g_p1 is in the ramp contact, where the paper puts it). Gaps of the
        // ramp faces are set so that in the rest configuration (pack just closed, xb = g_p2,
        // xm = xb + shaft gap, balls seated, equal angles) every face has the clearance g_p1.
        let xb0 = m.pack_clearance_m;
        let xm0 = xb0 + cfg.open.shaft_gap_m;
        let g2 = g - s * xb0;
        let g4 = g + s * xm0;
        let contacts = vec![
            c("c1", vec![(X_O, -1.0)], 0.0, 3.0),
            c(
                "c2+",
                vec![(THETA_S, rc), (THETA_C, -rc), (X_O, s), (X_B, -s)],
                g2,
                3.0,
            ),
            c(
                "c2-",
                vec![(THETA_S, -rc), (THETA_C, rc), (X_O, s), (X_B, -s)],
                g2,
                3.0,
            ),
            c("c3", vec![(X_I, 1.0)], 0.0, 3.0),
            c(
                "c4+",
                vec![(THETA_R, rc), (THETA_C, -rc), (X_M, s), (X_I, -s)],
                g4,
                3.0,
            ),
            c(
                "c4-",
                vec![(THETA_R, -rc), (THETA_C, rc), (X_M, s), (X_I, -s)],
                g4,
                3.0,
            ),
            c(
                "shafts",
                vec![(X_B, 1.0), (X_M, -1.0)],
                cfg.open.shaft_gap_m,
                1.0,
            ),
            c("pack", vec![(X_B, 1.0)], m.pack_clearance_m, 1.0),
        ];
        let law = ContactLaw {
            stiffness: m.contact_stiffness,
            restitution: m.restitution,
            approach_speed_floor_m_s: cfg.open.approach_speed_floor_m_s,
        };
        let n = contacts.len();
        Physical {
            cfg,
            faults: PhysicsFaults::default(),
            contacts,
            approach: vec![law.approach_speed_floor_m_s; n],
            mode: FrictionMode::Stuck,
            drive: cfg.drive,
            law,
            conservative: false,
        }
    }

    /// A lossless variant (no damping, no friction, no drive) for energy checks.
    pub fn conservative(mut self) -> Self {
        self.conservative = true;
        self.law = self.law.undamped();
        self.mode = FrictionMode::Free;
        self
    }

    /// Current friction mode of the pack.
    pub fn mode(&self) -> FrictionMode {
        self.mode
    }

    fn eval(&self, y: &[f64]) -> Eval {
        let m = &self.cfg.mechanism;
        let open = &self.cfg.open;
        let mut q = [0.0; N];
        let mut contact_n = [0.0; NC];
        for (k, c) in self.contacts.iter().enumerate() {
            let (mut d, v) = c.penetration(y);
            if k == PACK {
                d -= self.faults.extra_pack_clearance_m;
            }
            let f = self
                .law
                .force_n(d, v, self.approach.get(k).copied().unwrap_or(1.0));
            if let Some(slot) = contact_n.get_mut(k) {
                *slot = f;
            }
            // A ramp jam: the output balls cannot climb, so that share of their load is carried
            // by the socket wall as torque alone, with no axial push towards the pack.
            let jammed = if (1..=2).contains(&k) {
                1.0 - self.faults.ramp_jam
            } else {
                1.0
            };
            for &(i, coeff) in &c.terms {
                let axial = if i == X_O || i == X_B { jammed } else { 1.0 };
                if let Some(slot) = q.get_mut(i) {
                    *slot -= c.multiplicity * f * coeff * axial;
                }
            }
        }
        let pressing_n = contact_n.get(PACK).copied().unwrap_or(0.0);
        let mu_d = m.mu_dynamic;
        let lossy = if self.conservative { 0.0 } else { 1.0 };
        let g = GRAVITY_M_S2;
        let wsm = open.bearing_smoothing_rad_s;
        let vsm = open.axial_smoothing_m_s;
        // Bearing and guide frictions (smoothed Coulomb, μ_d).
        q[THETA_S] -= lossy
            * mu_d
            * m.output_shaft_mass_kg
            * g
            * m.output_friction_radius_m
            * smooth_sign(at(y, THETA_S + 1), wsm);
        q[THETA_R] -= lossy
            * mu_d
            * m.input_shaft_mass_kg
            * g
            * m.input_friction_radius_m
            * smooth_sign(at(y, THETA_R + 1), wsm);
        let conn_bearing = lossy
            * mu_d
            * m.connecting_shaft_mass_kg
            * g
            * m.connecting_friction_radius_m
            * smooth_sign(at(y, THETA_C + 1), wsm);
        let axial_f = lossy * mu_d * m.connecting_shaft_mass_kg * g;
        q[X_B] -= axial_f * smooth_sign(at(y, X_B + 1), vsm);
        q[X_M] -= axial_f * smooth_sign(at(y, X_M + 1), vsm);
        // Ball friction F_bf = μ_d·|F_c1 − F_c2| along the axis (cos θ component).
        let cth = m.socket_chamfer_rad.cos();
        let f1 = contact_n[0];
        let f2 = contact_n[1] + contact_n[2];
        q[X_O] -= lossy * 3.0 * mu_d * (f1 - f2).abs() * cth * smooth_sign(at(y, X_O + 1), vsm);
        let f3 = contact_n[3];
        let f4 = contact_n[4] + contact_n[5];
        q[X_I] -= lossy * 3.0 * mu_d * (f3 - f4).abs() * cth * smooth_sign(at(y, X_I + 1), vsm);
        // Wave spring (and a drag fault's extra force) on the big shaft.
        q[X_B] +=
            spring_force_n(m, at(y, X_B), self.faults.spring_scale) + self.faults.drag_force_n;
        // Load.
        q[THETA_S] += self.cfg.load_torque_nm;
        // Drive: proportional speed servo with the motor's torque limit.
        let drive_nm = if self.drive.on && !self.conservative {
            let motor = self.cfg.drive_torque_limit_nm();
            let lim = self
                .drive
                .torque_limit_nm
                .map_or(motor, |l| l.clamp(0.0, motor));
            (open.drive_gain_nm_s_rad * (self.drive.speed_ref_rad_s - at(y, THETA_R + 1)))
                .clamp(-lim, lim)
        } else {
            0.0
        };
        q[THETA_R] += drive_nm;
        // Pack on the connecting shaft.
        let cap = if self.conservative {
            PackCapacity {
                static_nm: 0.0,
                sliding_nm: 0.0,
            }
        } else {
            pack::capacity(m, pressing_n, self.faults.mu_scale, false)
        };
        let stuck = self.mode == FrictionMode::Stuck;
        let required_nm = q[THETA_C] - if stuck { 0.0 } else { conn_bearing };
        let pack_torque_nm = friction::torque_nm(self.mode, required_nm, cap);
        q[THETA_C] = required_nm + pack_torque_nm;
        // Accelerations.
        let mb3 = 3.0 * m.ball_mass_kg;
        let jb3 = 3.0 * m.ball_inertia_kg_m2;
        let inertia = [
            (
                THETA_R,
                m.input_inertia_kg_m2 + jb3 + open.reflected_motor_inertia_kg_m2,
            ),
            (X_I, mb3),
            (X_M, m.connecting_shaft_mass_kg),
            (THETA_C, m.connecting_inertia_kg_m2),
            (X_B, m.connecting_shaft_mass_kg),
            (X_O, mb3),
            (THETA_S, m.output_inertia_kg_m2 + jb3),
        ];
        let mut dy = [0.0; N];
        for &(i, mass) in &inertia {
            dy[i] = at(y, i + 1);
            dy[i + 1] = q[i] / mass;
        }
        if stuck && required_nm.abs() <= cap.static_nm {
            dy[THETA_C] = 0.0;
            dy[THETA_C + 1] = 0.0;
        }
        Eval {
            dy,
            contact_n,
            pressing_n,
            pack_torque_nm,
            required_nm,
            cap,
            drive_nm,
        }
    }

    fn settle_mode(&mut self, y: &mut [f64]) {
        if self.conservative {
            return;
        }
        // Decide with the torque the pack would have to hold (evaluate as if stuck).
        self.mode = FrictionMode::Stuck;
        let e = self.eval(y);
        self.mode = friction::settle(at(y, THETA_C + 1), e.required_nm, e.cap);
        if self.mode == FrictionMode::Stuck {
            put(y, THETA_C + 1, 0.0);
        }
    }
}

impl OdeSystem for Physical {
    fn dim(&self) -> usize {
        N
    }

    fn scales(&self) -> Vec<f64> {
        // angle 1e-2 rad, speed 1 rad/s, axial 1e-5 m
        let mut s = vec![0.0; N];
        for i in [THETA_R, THETA_C, THETA_S] {
            s[i] = 1e-2;
            s[i + 1] = 1.0;
        }
        // Axial speeds: the balls' light axial modes follow the stiff contacts quasi-statically;
        // holding their speeds to 1e-8 m/s would only resolve numerical jitter.
        for (i, speed_scale) in [(X_I, 0.1), (X_M, 0.1), (X_B, 0.1), (X_O, 0.1)] {
            s[i] = 1e-5;
            s[i + 1] = speed_scale;
        }
        s
    }

    fn rhs(&self, _t: f64, y: &[f64], dy: &mut [f64]) {
        let e = self.eval(y);
        dy.copy_from_slice(&e.dy);
    }

    fn event_count(&self) -> usize {
        self.contacts.len() + 1
    }

    fn events(&self, _t: f64, y: &[f64], g: &mut [f64]) {
        for (k, c) in self.contacts.iter().enumerate() {
            let (mut d, _) = c.penetration(y);
            if k == PACK {
                d -= self.faults.extra_pack_clearance_m;
            }
            put(g, k, d - TOUCH_EVENT_M);
        }
        let e = self.eval(y);
        put(
            g,
            self.contacts.len(),
            if self.conservative {
                1.0
            } else {
                friction::event_value(self.mode, at(y, THETA_C + 1), e.required_nm, e.cap)
            },
        );
    }

    fn on_event(&mut self, _t: f64, y: &mut [f64], fired: &[usize]) {
        for &k in fired {
            if let Some(c) = self.contacts.get(k) {
                let (d, v) = c.penetration(y);
                if let Some(a) = self.approach.get_mut(k) {
                    *a = if d >= 0.0 && v > 0.0 {
                        self.law.approach_speed_m_s(v)
                    } else {
                        self.law.approach_speed_floor_m_s
                    };
                }
            }
        }
        self.settle_mode(y);
    }
}

impl TwinModel for Physical {
    fn initial_state(&self) -> Vec<f64> {
        let m = &self.cfg.mechanism;
        let rc = m.socket_radius_m * m.socket_chamfer_rad.cos();
        let g = m.socket_clearance_m;
        let mut y = vec![0.0; N];
        let w0 = self.cfg.initial_speed_rad_s;
        for i in [THETA_R, THETA_C] {
            y[i + 1] = w0;
        }
        y[THETA_S + 1] = self.cfg.output_initial_speed_rad_s;
        // Pack just closed by the spring, shafts touching, balls resting on their shafts.
        let xb = m.pack_clearance_m;
        y[X_B] = xb;
        y[X_M] = xb + self.cfg.open.shaft_gap_m;
        // Output end: load face (plus) just touching: rc(θs − θc) + s(xo − xb) = g.
        let load_sign = super::load_sign(self.cfg.load_torque_nm);
        y[THETA_S] = load_sign * g / rc;
        // Input end: the faces the drive torque loads, if the drive is on.
        let drive_sign = if self.drive.on {
            if self.drive.speed_ref_rad_s >= 0.0 {
                1.0
            } else {
                -1.0
            }
        } else {
            0.0
        };
        y[THETA_R] = drive_sign * g / rc;
        y
    }

    fn set_drive(&mut self, drive: Drive, y: &mut [f64]) {
        self.drive = drive;
        self.settle_mode(y);
    }

    fn set_faults(&mut self, faults: PhysicsFaults, y: &mut [f64]) {
        self.faults = faults;
        self.settle_mode(y);
    }

    fn sample(&self, t: f64, y: &[f64]) -> Sample {
        let e = self.eval(y);
        Sample {
            t_s: t,
            output_angle_rad: at(y, THETA_S),
            output_speed_rad_s: at(y, THETA_S + 1),
            input_angle_rad: at(y, THETA_R),
            input_speed_rad_s: at(y, THETA_R + 1),
            drive_torque_nm: e.drive_nm,
            drive_on: self.drive.on,
            pressing_force_n: e.pressing_n,
            braking_torque_nm: e.pack_torque_nm.abs(),
            brake_state: if e.pressing_n > 0.0 {
                self.mode.brake_state()
            } else {
                0
            },
            contact_force_n: e.contact_n[1] + e.contact_n[2],
            input_contact_force_n: e.contact_n[4] + e.contact_n[5],
            ball_axial_m: at(y, X_O),
            shaft_axial_m: at(y, X_B),
        }
    }

    fn energy_j(&self, y: &[f64]) -> f64 {
        let m = &self.cfg.mechanism;
        let mb3 = 3.0 * m.ball_mass_kg;
        let jb3 = 3.0 * m.ball_inertia_kg_m2;
        let ke = 0.5
            * ((m.input_inertia_kg_m2 + jb3 + self.cfg.open.reflected_motor_inertia_kg_m2)
                * at(y, THETA_R + 1).powi(2)
                + mb3 * at(y, X_I + 1).powi(2)
                + m.connecting_shaft_mass_kg * at(y, X_M + 1).powi(2)
                + m.connecting_inertia_kg_m2 * at(y, THETA_C + 1).powi(2)
                + m.connecting_shaft_mass_kg * at(y, X_B + 1).powi(2)
                + mb3 * at(y, X_O + 1).powi(2)
                + (m.output_inertia_kg_m2 + jb3) * at(y, THETA_S + 1).powi(2));
        let mut pe = 0.0;
        for (k, c) in self.contacts.iter().enumerate() {
            let (mut d, _) = c.penetration(y);
            if k == PACK {
                d -= self.faults.extra_pack_clearance_m;
            }
            pe += c.multiplicity * self.law.energy_j(d);
        }
        let x = at(y, X_B);
        let compression = (m.spring_preload_m - x).max(0.0);
        pe += 0.5 * m.spring_stiffness_n_m * self.faults.spring_scale * compression * compression;
        pe -= self.cfg.load_torque_nm * at(y, THETA_S);
        ke + pe
    }
}
