//! The unit's configuration block in the last flash sector (`memory.x`: `CONFIG`), written at
//! commissioning apart from the code (`noback::monitor::config_block`). Under QEMU the xtask
//! loads a block there with `-device loader`; a semihosting `config=FILE` takes precedence.

use noback::monitor::config_block::{self, ConfigBlockError, CONFIG_BLOCK_BYTES};
use noback::monitor::Config;

extern "C" {
    /// The configuration sector's first byte (`memory.x`).
    static __config_block: u8;
}

/// The configuration and where it came from. No block (an erased sector) or a refused one leaves
/// the monitor uncommissioned, which trusts no estimate, and says so on the log.
pub fn configuration() -> (Config, &'static str) {
    // SAFETY: `memory.x` places `__config_block` at the start of a 128 KiB flash sector that
    // nothing writes while the firmware runs; `CONFIG_BLOCK_BYTES` lie within it.
    #[allow(unsafe_code)]
    let block = unsafe {
        core::slice::from_raw_parts(core::ptr::addr_of!(__config_block), CONFIG_BLOCK_BYTES)
    };
    match config_block::decode(block) {
        Ok(c) => (c, "from its block"),
        Err(ConfigBlockError::Magic) => (Config::default(), "uncommissioned"),
        Err(_) => {
            defmt::error!("the configuration block is refused (torn, corrupt or rejected)");
            (Config::default(), "uncommissioned (its block refused)")
        }
    }
}
