//! The plant family of the Monte Carlo (issue 16): the real actuator lies somewhere among the
//! twin's two readings of the paper and the quantities the paper leaves open. A draw of the
//! `plant` family picks the reading and each open quantity over the range argued in
//! docs/model.md ("The plant family"); the `physical-default` family keeps the physical reading
//! with its defaults (Table 2 ± 10 % is drawn in both).

use noback::monitor::Config;
use noback_twin::reading::Reading;
use noback_twin::scene::Scene;
use noback_twin::sensing::Rng;

/// Which plants a campaign draws from.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Family {
    /// The physical reading with its open-item defaults (the campaigns before issue 16).
    PhysicalDefault,
    /// Both readings and every open quantity over its range.
    Plant,
}

impl Family {
    /// Every family, by name.
    pub const ALL: [Family; 2] = [Family::PhysicalDefault, Family::Plant];

    /// The name a part file records.
    pub const fn name(self) -> &'static str {
        match self {
            Family::PhysicalDefault => "physical-default",
            Family::Plant => "plant",
        }
    }

    /// The monitor a campaign of this family runs: the physical reading's own settings on its
    /// plant, the uncommissioned defaults on the whole family.
    pub fn config(self) -> Config {
        match self {
            Family::PhysicalDefault => Config::physical_reading(),
            Family::Plant => Config::default(),
        }
    }

    /// The family an example's arguments name: `plant`, else the physical default.
    pub fn from_args(args: &[String]) -> Family {
        if args.iter().any(|a| a == "plant") {
            Family::Plant
        } else {
            Family::PhysicalDefault
        }
    }

    /// Parses a name.
    pub fn parse(name: &str) -> Option<Family> {
        Family::ALL.into_iter().find(|f| f.name() == name)
    }
}

/// A plant's form, as reports group runs: the reading.
pub fn form(scene: &Scene) -> &'static str {
    match scene.reading {
        Reading::Paper => "paper",
        Reading::Physical => "physical",
    }
}

/// Draws the plant's form onto `scene` (after every draw of the default family, so the
/// default family's draws are unchanged).
pub fn draw_form(scene: &mut Scene, rng: &mut Rng) {
    let mut between = |lo: f64, hi: f64| lo + (hi - lo) * rng.uniform();
    let reading = if between(0.0, 1.0) < 0.5 {
        Reading::Paper
    } else {
        Reading::Physical
    };
    // Contact damping's reference speed: log-uniform over a decade around the default.
    let damping_ref = 0.01 * 10_f64.powf(between(-0.5, 0.5));
    // Ramp lost motion (paper reading): half to twice Table 2's 2·g_p1/(r·cosθ) = 0.028 rad.
    let backlash = between(0.014, 0.056);
    // The slipping pack: μ_s (the paper's levels) or μ_d.
    let sliding_static = between(0.0, 1.0) < 0.5;
    let efficiency = between(0.80, 0.95);
    let kt_scale = between(0.9, 1.1);
    let servo_scale = 2_f64.powf(between(-1.0, 1.0));
    let gain = between(0.97, 1.03);
    let offset = between(-0.25, 0.25);
    scene.reading = reading;
    scene.open.approach_speed_floor_m_s = damping_ref;
    scene.open.paper_backlash_rad = backlash;
    scene.open.paper_sliding_mu_static = sliding_static;
    scene.open.drive_gain_nm_s_rad *= servo_scale;
    scene.sensors.reducer_efficiency = efficiency;
    scene.sensors.motor_torque_constant_nm_a *= kt_scale;
    scene.noise.current_gain = gain;
    scene.noise.current_offset_a = offset;
}

/// The examples' leading `[RUNS] [SEED]` arguments, each defaulted when absent. A value that is
/// not a whole number ends the program with one line naming it and exit code 2, as the xtask's
/// commands do.
pub fn runs_and_seed(args: &mut impl Iterator<Item = String>, runs: u64, seed: u64) -> (u64, u64) {
    let mut next = |default: u64, name: &str| match args.next() {
        None => default,
        Some(s) => s.parse().unwrap_or_else(|e| {
            eprintln!("error: {name} '{s}' is not a whole number ({e})");
            std::process::exit(2)
        }),
    };
    (next(runs, "RUNS"), next(seed, "SEED"))
}

/// A family example's command line: `[RUNS] [SEED]` ([`runs_and_seed`]), then words, among
/// which `plant` picks [`Family::Plant`].
pub struct ExampleArgs {
    pub runs: u64,
    pub seed: u64,
    pub family: Family,
    /// The words after `[RUNS] [SEED]`.
    pub rest: Vec<String>,
}

impl ExampleArgs {
    /// The process's arguments, `RUNS` and `SEED` defaulted to `runs` and `seed`.
    pub fn parse(runs: u64, seed: u64) -> ExampleArgs {
        let mut args = std::env::args().skip(1);
        let (runs, seed) = runs_and_seed(&mut args, runs, seed);
        let rest: Vec<String> = args.collect();
        let family = Family::from_args(&rest);
        ExampleArgs {
            runs,
            seed,
            family,
            rest,
        }
    }

    /// Whether `word` was given.
    pub fn has(&self, word: &str) -> bool {
        self.rest.iter().any(|a| a == word)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use noback_twin::scene::SceneKind;

    #[test]
    fn names_round_trip_and_draws_stay_in_range() {
        for f in Family::ALL {
            assert_eq!(Family::parse(f.name()), Some(f));
        }
        assert_eq!(Family::parse("plants"), None);
        let mut rng = Rng::new(7);
        let mut readings = [0; 2];
        for _ in 0..200 {
            let mut s = Scene::builtin(SceneKind::Hold, Reading::Physical);
            draw_form(&mut s, &mut rng);
            readings[usize::from(s.reading == Reading::Physical)] += 1;
            assert!((0.0031..0.032).contains(&s.open.approach_speed_floor_m_s));
            assert!((0.80..=0.95).contains(&s.sensors.reducer_efficiency));
            assert!((0.97..=1.03).contains(&s.noise.current_gain));
            assert!(s.noise.current_offset_a.abs() <= 0.25);
        }
        assert!(readings.iter().all(|&n| n > 60), "{readings:?}");
    }
}
