//! The unit's configuration block in the last flash sector (`memory.x`: `CONFIG`), written at
//! commissioning apart from the code (`noback::monitor::config_block`). Under QEMU the xtask
//! loads a block there with `-device loader`; a semihosting `config=FILE` takes precedence.

use noback::monitor::config_block::{self, ConfigBlockError, CONFIG_BLOCK_BYTES};

extern "C" {
    /// The configuration sector's first byte (`memory.x`).
    static __config_block: u8;
}

/// `Config::default()`'s block, converted by build.rs: the part converts no units.
static UNCOMMISSIONED: &[u8] = include_bytes!(concat!(env!("OUT_DIR"), "/uncommissioned.nbc"));

/// The unit's block and where it comes from, or `Config::default()`'s when the sector is erased
/// (no block) or its block is refused (logged). Either leaves the monitor uncommissioned, which
/// trusts no estimate. Out of line: this check's decoding leaves the stack before `install`'s.
#[inline(never)]
pub fn block() -> (&'static [u8], &'static str) {
    // SAFETY: `memory.x` places `__config_block` at the start of a 128 KiB flash sector that
    // nothing writes while the firmware runs; `CONFIG_BLOCK_BYTES` lie within it.
    #[allow(unsafe_code)]
    let block = unsafe {
        core::slice::from_raw_parts(core::ptr::addr_of!(__config_block), CONFIG_BLOCK_BYTES)
    };
    match config_block::read(block, |_| ()) {
        Ok(()) => (block, "from its block"),
        Err(ConfigBlockError::Magic) => (UNCOMMISSIONED, "uncommissioned"),
        Err(_) => {
            defmt::error!("the configuration block is refused (torn or corrupt)");
            (UNCOMMISSIONED, "uncommissioned (its block refused)")
        }
    }
}
