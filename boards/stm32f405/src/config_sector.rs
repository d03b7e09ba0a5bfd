//! The unit's configuration block in the last flash sector (`memory.x`: `CONFIG`), written at
//! commissioning apart from the code (`noback::monitor::config_block`). Under QEMU the xtask
//! loads a block there with `-device loader`; a semihosting `config=FILE` takes precedence.

use noback::monitor::config_block::{self, ConfigBlockError, CONFIG_BLOCK_BYTES};
use noback::monitor::Monitor;

extern "C" {
    /// The configuration sector's first byte (`memory.x`).
    static __config_block: u8;
}

/// `Config::default()`'s block, converted by build.rs: the part converts no units.
static UNCOMMISSIONED: &[u8] = include_bytes!(concat!(env!("OUT_DIR"), "/uncommissioned.nbc"));

/// The monitor on the unit's block and where its settings came from. No block (an erased
/// sector) or a refused one leaves the monitor uncommissioned, which trusts no estimate, and
/// says so on the log.
pub fn monitor() -> (Monitor, &'static str) {
    // SAFETY: `memory.x` places `__config_block` at the start of a 128 KiB flash sector that
    // nothing writes while the firmware runs; `CONFIG_BLOCK_BYTES` lie within it.
    #[allow(unsafe_code)]
    let block = unsafe {
        core::slice::from_raw_parts(core::ptr::addr_of!(__config_block), CONFIG_BLOCK_BYTES)
    };
    let source = match config_block::decode(block) {
        Ok(monitor) => return (monitor, "from its block"),
        Err(ConfigBlockError::Magic) => "uncommissioned",
        Err(_) => {
            defmt::error!("the configuration block is refused (torn or corrupt)");
            "uncommissioned (its block refused)"
        }
    };
    match config_block::decode(UNCOMMISSIONED) {
        Ok(monitor) => (monitor, source),
        Err(_) => crate::clock::halt("the uncommissioned block does not decode"),
    }
}
