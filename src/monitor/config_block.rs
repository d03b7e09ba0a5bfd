//! The configuration block: a unit's settings as bytes, converted from its commissioned
//! [`Config`] on the ground and kept apart from the code (a parameter data item: one firmware
//! image for every unit, each with its own block). The flight image carries no unit conversion.
//!
//! | bytes | what |
//! |---|---|
//! | 4 | magic `NBCG` (a later layout of the settings changes it) |
//! | n | the monitor's settings (`Settings::new` of the `Config`), postcard |
//! | 4 | CRC-32/ISCSI of the settings' bytes, little-endian (postcard's `use-crc` flavour) |
//!
//! [`encode`] refuses a `Config` that [`Monitor::new`] rejects; [`decode`] refuses a block that
//! is short, of another layout or corrupt, with its reason.

use super::settings::Settings;
use super::{Config, ConfigError, Monitor};
use crc::{Crc, CRC_32_ISCSI};

/// The block's first bytes.
pub const CONFIG_BLOCK_MAGIC: [u8; 4] = *b"NBCG";
/// Room the firmware keeps for a block (the default settings' block takes 320 bytes).
pub const CONFIG_BLOCK_BYTES: usize = 1024;

const CRC: Crc<u32> = Crc::<u32>::new(&CRC_32_ISCSI);

/// Why a block was refused.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ConfigBlockError {
    /// Not a block of this layout (magic).
    Magic,
    /// The buffer is too small for the block (writing), or the block ends early (reading).
    Size,
    /// The checksum or the encoding does not match: a torn or corrupt block.
    Corrupt,
    /// A configuration `Monitor::new` rejects (writing).
    Rejected(ConfigError),
}

/// Converts `c` and writes its block into `buf`; returns its length.
pub fn encode(c: &Config, buf: &mut [u8]) -> Result<usize, ConfigBlockError> {
    let settings = Settings::new(c).map_err(ConfigBlockError::Rejected)?;
    let (head, body) = buf.split_at_mut_checked(4).ok_or(ConfigBlockError::Size)?;
    head.copy_from_slice(&CONFIG_BLOCK_MAGIC);
    let n = postcard::to_slice_crc32(&settings, body, CRC.digest())
        .map_err(|_| ConfigBlockError::Size)?
        .len();
    Ok(4 + n)
}

/// The monitor at power-on on a block's settings (trailing bytes after it are ignored).
pub fn decode(bytes: &[u8]) -> Result<Monitor, ConfigBlockError> {
    read(bytes, Monitor::with_settings)
}

/// `f` of a block's settings (trailing bytes after it are ignored). `f` runs where they were
/// decoded, so a firmware builds its monitor in a static with one copy of them on the stack.
#[inline(always)]
pub fn read<T>(bytes: &[u8], f: impl FnOnce(&Settings) -> T) -> Result<T, ConfigBlockError> {
    let (head, body) = bytes.split_at_checked(4).ok_or(ConfigBlockError::Size)?;
    if head != CONFIG_BLOCK_MAGIC {
        return Err(ConfigBlockError::Magic);
    }
    match postcard::take_from_bytes_crc32::<Settings>(body, CRC.digest()) {
        Ok((settings, _)) => Ok(f(&settings)),
        Err(postcard::Error::DeserializeUnexpectedEnd) => Err(ConfigBlockError::Size),
        Err(_) => Err(ConfigBlockError::Corrupt),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::monitor::Inputs;

    #[test]
    fn a_block_gives_the_monitor_its_config_builds_and_a_changed_bit_is_refused() {
        let mut c = Config::physical_reading();
        c.sliding_mu = 0.21;
        let mut buf = [0_u8; CONFIG_BLOCK_BYTES];
        let n = encode(&c, &mut buf).unwrap();
        assert!(n < CONFIG_BLOCK_BYTES);
        let mut from_block = decode(&buf[..n]).unwrap();
        let mut built = Monitor::new(c).unwrap();
        assert_eq!(from_block.settings, built.settings);
        for i in 0..500_u32 {
            let inputs = Inputs::new(2048 + (i % 7) as u16, i * 3, i * 40, i > 100);
            assert_eq!(from_block.step(&inputs), built.step(&inputs), "tick {i}");
        }
        for at in [0, 4, n / 2, n - 1] {
            let mut bad = buf;
            bad[at] ^= 0x10;
            assert!(decode(&bad[..n]).is_err(), "bit flipped at {at}");
        }
        assert!(matches!(decode(&buf[..n - 2]), Err(ConfigBlockError::Size)));
        assert!(encode(&c, &mut buf[..40]).is_err());
    }

    #[test]
    fn a_config_the_monitor_rejects_gives_no_block() {
        let c = Config {
            sliding_mu: -1.0,
            ..Config::default()
        };
        let mut buf = [0_u8; CONFIG_BLOCK_BYTES];
        assert!(matches!(
            encode(&c, &mut buf),
            Err(ConfigBlockError::Rejected(_))
        ));
    }

    /// The default settings' block, its length and checksum: a change here is a change of the
    /// settings' layout or of a default; a layout change must also change the magic.
    #[test]
    fn the_default_block_is_the_one_recorded() {
        let mut buf = [0_u8; CONFIG_BLOCK_BYTES];
        let n = encode(&Config::default(), &mut buf).unwrap();
        let crc = u32::from_le_bytes(buf[n - 4..n].try_into().unwrap());
        assert_eq!(
            (n, crc),
            (320, 0x2241_D3B6),
            "length and CRC of the default block"
        );
    }
}
