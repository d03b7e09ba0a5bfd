//! Target tests: run under QEMU on M0, M3 and M4F by `cargo xtask test` (defmt-test harness).
//!
//! Each test here runs the same code and the same vectors as the host tests; the digest it logs
//! is compared by the xtask with the host's, which is how bit-identity is checked.
#![cfg_attr(target_os = "none", no_std, no_main)]

#[cfg(target_os = "none")]
#[defmt_test::tests]
mod tests {
    use noback as _; // panic handler, HardFault exit, defmt transport

    #[test]
    fn fixed_point_vectors_match_reference() {
        let report = noback::vectors::run();
        defmt::info!(
            "fx-selfcheck cases={=u32} mismatches={=u32} digest={=u32:#010x}",
            report.cases,
            report.mismatches,
            report.digest
        );
        defmt::assert_eq!(report.mismatches, 0);
    }

    #[test]
    fn counter_delta_wraps_on_target() {
        defmt::assert_eq!(noback::fx::counter_delta(16_383, 0, 14), 1);
        defmt::assert_eq!(noback::fx::counter_delta(0, 16_383, 14), -1);
    }

    #[test]
    fn static_pack_levels_on_target() {
        let m = noback::mechanism::TABLE2;
        let spring_only = m.pack_capacity_nm(m.spring_preload_n(), m.mu_static);
        defmt::assert!((spring_only - 8.43).abs() < 0.01);
    }
}

/// On the host this target test is a stub; `cargo xtask test` runs it under QEMU.
#[cfg(not(target_os = "none"))]
fn main() {
    println!("on_target runs under QEMU: use `cargo xtask test`");
}
