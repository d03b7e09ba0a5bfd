//! Cost bench of the reduced-model variants (issue 6): every number format × integrator of
//! `noback_study::reduced` steps the paper's reverse-load braking at 10 kHz from the drive cut until
//! the pack has held for a while, each step measured alone with SysTick (`Meter`), for
//! deterministic instruction counts under QEMU `-icount` (`cargo xtask bench` boots it on the
//! Cortex-M3 and converts ticks to instructions as `cargo xtask run` does).
//!
//! One line per variant: `variant fmt=… method=… steps=… ticks_sum=… ticks_max=… overhead=…
//! theta_bits=…` (the final angle's bits keep the work observable), then `bench-done`.
#![cfg_attr(target_os = "none", no_std, no_main)]

#[cfg(target_os = "none")]
mod target {
    use cortex_m_rt::entry;
    use fixed::types::{I16F16, I32F32};
    use noback::mechanism::TABLE2;
    use noback::platform::{self, meter::Meter};
    use noback_study::reduced::num::{Real, Widen};
    use noback_study::reduced::{BrakingScene, Method, Params, Reduced};

    /// Step rate of the measured runs.
    const RATE_HZ: u32 = 10_000;
    /// Steps measured per variant: 0.3 s after the cut (slip, reversal, lock, hold).
    const STEPS: u32 = 3_000;

    fn measure<N: Real + Widen<A>, A: Real>(meter: &Meter, method: Method, name: &str) {
        let p = Params::from_mechanism(&TABLE2, TABLE2.load_torque_nm, f64::from(RATE_HZ));
        let mut m = Reduced::<N, A>::new(p, method);
        m.set_drive(true, BrakingScene::REVERSE.speed_ref_rad_s);
        m.step();
        m.set_drive(false, 0.0);
        let (a, b) = (meter.now(), meter.now());
        let overhead = Meter::ticks(a, b);
        let (mut sum, mut max) = (0_u64, 0_u32);
        for _ in 0..STEPS {
            let start = meter.now();
            m.step();
            let ticks = Meter::ticks(start, meter.now()).saturating_sub(overhead);
            core::hint::black_box(&m);
            sum += u64::from(ticks);
            max = max.max(ticks);
        }
        let theta_bits = m.state.theta.to_f64().to_bits();
        defmt::info!(
            "variant fmt={=str} method={=str} steps={=u32} ticks_sum={=u64} ticks_max={=u32} overhead={=u32} theta_bits={=u64:#x}",
            name,
            method.name(),
            STEPS,
            sum,
            max,
            overhead,
            theta_bits
        );
    }

    #[entry]
    fn main() -> ! {
        let Some(peripherals) = cortex_m::Peripherals::take() else {
            platform::exit(noback::exit_code::SELFCHECK_FAILED)
        };
        let meter = Meter::start(peripherals.SYST);
        for method in Method::ALL {
            measure::<f64, f64>(&meter, method, "f64");
            measure::<f32, f32>(&meter, method, "f32");
            measure::<I16F16, I16F16>(&meter, method, "I16F16");
            measure::<I32F32, I32F32>(&meter, method, "I32F32");
            measure::<I16F16, I32F32>(&meter, method, "I16F16+I32F32");
        }
        defmt::info!("bench-done");
        platform::exit(noback::exit_code::SUCCESS)
    }
}

/// On the host this binary only says where it runs.
#[cfg(not(target_os = "none"))]
fn main() {
    println!("noback-bench runs on a Cortex-M: use `cargo xtask bench` to boot it under QEMU");
}
