//! The monitor's state as bytes, for the trip log (`crate::trip_log`): saved with postcard
//! through the state types' serde derives, restored next to settings rebuilt from the same
//! configuration, and a digest of those settings to tell configurations apart.

use super::{Config, ConfigError, Monitor};

/// Why a saved state could not be written or read back.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SnapshotError {
    /// The buffer is too small for the state.
    BufferFull,
    /// The bytes are not a state this build saved.
    Corrupt,
    /// The configuration was rejected.
    Config(ConfigError),
}

/// A `Hasher` that folds the bytes into the FNV-1a digest.
struct DigestHasher(crate::digest::Fnv1a);

impl core::hash::Hasher for DigestHasher {
    fn write(&mut self, bytes: &[u8]) {
        bytes.iter().for_each(|b| self.0.push_byte(*b));
    }
    // Pointer-sized values (lengths, enum discriminants) as 32 bits: host and target agree.
    fn write_usize(&mut self, i: usize) {
        self.write(&(i as u32).to_le_bytes());
    }
    fn write_isize(&mut self, i: isize) {
        self.write(&(i as i32).to_le_bytes());
    }
    fn finish(&self) -> u64 {
        u64::from(self.0.value())
    }
}

/// The monitor's state as bytes (postcard), for a trip record: a monitor restored from them
/// with the same configuration steps on exactly as the one that saved them.
impl Monitor {
    /// Writes the state (everything but the settings, which the configuration gives) into
    /// `buf`; returns the bytes used.
    pub fn save_state<'b>(&self, buf: &'b mut [u8]) -> Result<&'b mut [u8], SnapshotError> {
        postcard::to_slice(&(&self.state, &self.job, self.job_due), buf)
            .map_err(|_| SnapshotError::BufferFull)
    }

    /// FNV-1a over the settings (`Hash`): which configuration a saved state belongs with.
    pub fn settings_digest(&self) -> u32 {
        use core::hash::Hash;
        let mut h = DigestHasher(crate::digest::Fnv1a::new());
        self.settings.hash(&mut h);
        h.0.value()
    }

    /// The monitor `config` builds, in the state `bytes` (from [`Monitor::save_state`]).
    pub fn restore(config: Config, bytes: &[u8]) -> Result<Monitor, SnapshotError> {
        let mut monitor = Monitor::new(config).map_err(SnapshotError::Config)?;
        let (state, job, job_due) =
            postcard::from_bytes(bytes).map_err(|_| SnapshotError::Corrupt)?;
        (monitor.state, monitor.job, monitor.job_due) = (state, job, job_due);
        Ok(monitor)
    }
}
