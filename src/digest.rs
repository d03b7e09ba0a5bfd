//! FNV-1a over 32-bit words: the running digest the host and the targets compare bit for bit.
//!
//! Not a cryptographic hash; it only has to change when any bit of any word changes, cheaply
//! (four multiplies a word) on an M0.

/// A running FNV-1a (32-bit) digest.
///
/// ```
/// use noback::digest::Fnv1a;
/// let mut a = Fnv1a::new();
/// a.push(1);
/// let mut b = Fnv1a::new();
/// b.push(2);
/// assert_ne!(a.value(), b.value());
/// ```
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Fnv1a(u32);

impl Default for Fnv1a {
    fn default() -> Self {
        Self::new()
    }
}

impl Fnv1a {
    /// The FNV offset basis.
    pub const fn new() -> Fnv1a {
        Fnv1a(0x811C_9DC5)
    }

    /// Folds one word in (little-endian bytes, wrapping multiply by the FNV prime).
    pub fn push(&mut self, word: u32) {
        for byte in word.to_le_bytes() {
            self.push_byte(byte);
        }
    }

    /// Folds one byte in.
    pub fn push_byte(&mut self, byte: u8) {
        self.0 = (self.0 ^ u32::from(byte)).wrapping_mul(0x0100_0193);
    }

    /// The digest so far.
    pub const fn value(&self) -> u32 {
        self.0
    }
}
