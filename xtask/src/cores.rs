//! The emulated Cortex-M cores we test on, and how QEMU boots each.
//!
//! One memory map (`memory.x`: 256 K flash at 0x0, 64 K RAM at 0x2000_0000) fits every board.
//! Hard-float code faults on lm3s6965evb at its first VFP instruction, so the M4F runs on
//! mps2-an386, which has the FPU. The M7 (mps2-an500) runs the M4F's image: same target, so
//! the cargo runner's tests (which pick the core from the target) run on the M4F only.

/// The STM32F405 board crate's manifest (its own workspace).
pub const BOARD_MANIFEST: &str = "boards/stm32f405/Cargo.toml";

/// Where a firmware image is built from.
#[derive(Clone, Copy, Debug)]
pub enum Firmware {
    /// A package of the root workspace (`-p`).
    Package(&'static str),
    /// A crate with a workspace of its own (`--manifest-path`, relative to the root).
    Manifest(&'static str),
}

/// A core under test.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Core {
    /// Cortex-M0 (ARMv6-M): lm3s6965evb with `-cpu cortex-m0`.
    M0,
    /// Cortex-M3 (ARMv7-M): lm3s6965evb.
    M3,
    /// Cortex-M4 with FPU (ARMv7E-M, hard float): mps2-an386.
    M4f,
    /// Cortex-M7 with FPU (ARMv7E-M, hard float): mps2-an500, the M4F's image.
    M7,
    /// Cortex-M4F in a real part, an STM32F405: netduinoplus2 booting the board crate's image
    /// (`boards/stm32f405`, chosen by `--board stm32f405`, not `--core`).
    Stm32f405,
}

impl Core {
    /// The cores with a target of their own, in test order (every test stage runs on each).
    pub const ALL: [Core; 3] = [Core::M0, Core::M3, Core::M4f];
    /// Every core `--core` accepts: `ALL` and the M7, which shares the M4F's target.
    pub const EVERY: [Core; 4] = [Core::M0, Core::M3, Core::M4f, Core::M7];

    /// Name on the command line.
    pub fn name(self) -> &'static str {
        match self {
            Core::M0 => "m0",
            Core::M3 => "m3",
            Core::M4f => "m4f",
            Core::M7 => "m7",
            Core::Stm32f405 => "stm32f405",
        }
    }

    /// Rust target triple.
    pub fn triple(self) -> &'static str {
        match self {
            Core::M0 => "thumbv6m-none-eabi",
            Core::M3 => "thumbv7m-none-eabi",
            Core::M4f | Core::M7 | Core::Stm32f405 => "thumbv7em-none-eabihf",
        }
    }

    /// QEMU `-machine` and `-cpu`.
    pub fn machine_cpu(self) -> (&'static str, &'static str) {
        match self {
            Core::M0 => ("lm3s6965evb", "cortex-m0"),
            Core::M3 => ("lm3s6965evb", "cortex-m3"),
            Core::M4f => ("mps2-an386", "cortex-m4"),
            Core::M7 => ("mps2-an500", "cortex-m7"),
            Core::Stm32f405 => ("netduinoplus2", "cortex-m4"),
        }
    }

    /// Processor clock of the board under QEMU (Hz): what the firmware's `Meter` (SysTick on the
    /// core clock) counts.
    pub fn systick_clock_hz(self) -> f64 {
        match self {
            Core::M0 | Core::M3 => 12.5e6,
            Core::M4f | Core::M7 => 25.0e6,
            // QEMU's netduinoplus2 runs the core at the part's 168 MHz.
            Core::Stm32f405 => 168.0e6,
        }
    }

    /// The manifest (a workspace of its own for a board crate, else the root's package) and
    /// binary of the firmware image this core boots.
    pub fn firmware(self) -> (Firmware, &'static str) {
        match self {
            Core::Stm32f405 => (Firmware::Manifest(BOARD_MANIFEST), "noback-stm32f405"),
            _ => (Firmware::Package("noback"), "noback-fw"),
        }
    }

    /// The core's clock in flight (Hz), for the share of the deadline a tick takes: the
    /// STM32F405's 168 MHz, else the 100 MHz reference of the cost line.
    pub fn flight_clock_hz(self) -> f64 {
        match self {
            Core::Stm32f405 => 168.0e6,
            _ => 100.0e6,
        }
    }

    /// SysTick ticks per executed instruction under `-icount shift=N` (2^N ns per instruction).
    pub fn ticks_per_insn(self, shift: u32) -> f64 {
        f64::from(1_u32 << shift) * 1e-9 * self.systick_clock_hz()
    }

    /// Parses a command-line name (`m0`, `m3`, `m4f`, `m7`).
    pub fn parse(name: &str) -> Result<Core, String> {
        Core::EVERY
            .into_iter()
            .find(|c| c.name() == name)
            .ok_or_else(|| format!("unknown core `{name}` (expected m0, m3, m4f or m7)"))
    }

    /// The core whose target triple appears in a build path, e.g.
    /// `target/thumbv6m-none-eabi/debug/deps/on_target-…`.
    pub fn from_path(path: &str) -> Option<Core> {
        Core::ALL.into_iter().find(|c| path.contains(c.triple()))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cores_round_trip_and_are_found_in_paths() {
        for core in Core::ALL {
            assert_eq!(Core::parse(core.name()), Ok(core));
            let path = format!("/w/target/{}/release/noback-fw", core.triple());
            assert_eq!(Core::from_path(&path), Some(core));
        }
        assert_eq!(Core::parse("m7"), Ok(Core::M7));
        // A path names its target, which the M7 shares with the M4F: the runner takes the M4F.
        assert_eq!(
            Core::from_path("/w/target/thumbv7em-none-eabihf/debug/deps/on_target-1"),
            Some(Core::M4f)
        );
        assert!(Core::parse("m9").is_err());
        assert_eq!(Core::from_path("target/debug/xtask"), None);
    }
}
