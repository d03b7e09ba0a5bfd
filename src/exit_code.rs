//! Exit codes a target run ends with under QEMU (semihosting exit), shared with the xtask that
//! checks them. Portable on purpose: the host side must agree with the target on each number.

/// The run ended normally.
pub const SUCCESS: i32 = 0;
/// A self-check on the target found a mismatch.
pub const SELFCHECK_FAILED: i32 = 1;
/// A panic (the real-time core has no panic paths; this catches the rest).
pub const PANIC: i32 = 101;
/// A HardFault.
pub const HARDFAULT: i32 = 102;
