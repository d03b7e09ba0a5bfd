//! The configuration block: a unit's commissioned [`Config`] as bytes, kept apart from the code
//! (a parameter data item: one firmware image for every unit, each with its own block).
//!
//! | bytes | what |
//! |---|---|
//! | 4 | magic `NBC1` (a later layout changes it) |
//! | n | the `Config`, postcard |
//! | 4 | CRC-32/ISCSI of the `Config`'s bytes, little-endian (postcard's `use-crc` flavour) |
//!
//! A block that is short, of another layout, corrupt or rejected by [`Monitor::new`] is refused
//! with its reason; the firmware then does not start the monitor on it.

use super::{Config, ConfigError, Monitor};
use crc::{Crc, CRC_32_ISCSI};

/// The block's first bytes.
pub const CONFIG_BLOCK_MAGIC: [u8; 4] = *b"NBC1";
/// Room the firmware keeps for a block (a `Config` takes about 560 bytes).
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
    /// A whole block whose configuration `Monitor::new` rejects.
    Rejected(ConfigError),
}

/// Writes `c`'s block into `buf`; returns its length.
pub fn encode(c: &Config, buf: &mut [u8]) -> Result<usize, ConfigBlockError> {
    let (head, body) = buf.split_at_mut_checked(4).ok_or(ConfigBlockError::Size)?;
    head.copy_from_slice(&CONFIG_BLOCK_MAGIC);
    let n = postcard::to_slice_crc32(c, body, CRC.digest())
        .map_err(|_| ConfigBlockError::Size)?
        .len();
    Ok(4 + n)
}

/// Reads a block (trailing bytes after it are ignored) and checks that the monitor accepts it.
pub fn decode(bytes: &[u8]) -> Result<Config, ConfigBlockError> {
    let (head, body) = bytes.split_at_checked(4).ok_or(ConfigBlockError::Size)?;
    if head != CONFIG_BLOCK_MAGIC {
        return Err(ConfigBlockError::Magic);
    }
    let c: Config = postcard::take_from_bytes_crc32(body, CRC.digest())
        .map(|(c, _)| c)
        .map_err(|e| match e {
            postcard::Error::DeserializeUnexpectedEnd => ConfigBlockError::Size,
            _ => ConfigBlockError::Corrupt,
        })?;
    Monitor::new(c).map_err(ConfigBlockError::Rejected)?;
    Ok(c)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_block_reads_back_and_a_changed_bit_is_refused() {
        let mut c = Config::physical_reading();
        c.sliding_mu = 0.21;
        let mut buf = [0_u8; CONFIG_BLOCK_BYTES];
        let n = encode(&c, &mut buf).unwrap();
        assert!(n < CONFIG_BLOCK_BYTES);
        assert_eq!(decode(&buf[..n]), Ok(c));
        for at in [0, 4, n / 2, n - 1] {
            let mut bad = buf;
            bad[at] ^= 0x10;
            assert!(decode(&bad[..n]).is_err(), "bit flipped at {at}");
        }
        assert_eq!(decode(&buf[..n - 2]), Err(ConfigBlockError::Size));
        assert!(encode(&c, &mut buf[..40]).is_err());
    }

    #[test]
    fn a_whole_block_the_monitor_rejects_is_refused() {
        let c = Config {
            sliding_mu: -1.0,
            ..Config::default()
        };
        let mut buf = [0_u8; CONFIG_BLOCK_BYTES];
        let n = encode(&c, &mut buf).unwrap();
        assert!(matches!(
            decode(&buf[..n]),
            Err(ConfigBlockError::Rejected(_))
        ));
    }
}
