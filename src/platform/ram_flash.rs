//! A NOR flash in RAM for the trip log under QEMU, whose boards' flash cannot be programmed
//! from the guest: the same `NorFlash` contract as a part's driver (programming only clears
//! bits, an erase sets a page to 0xFF), so the store runs the code it runs on a part.

use embedded_storage_async::nor_flash::{
    ErrorType, NorFlash, NorFlashError, NorFlashErrorKind, ReadNorFlash,
};

/// An access outside the region or not aligned to its units.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct OutOfRange;

impl NorFlashError for OutOfRange {
    fn kind(&self) -> NorFlashErrorKind {
        NorFlashErrorKind::OutOfBounds
    }
}

/// `N` bytes of RAM in erase pages of `PAGE` bytes, programmed by 4-byte words.
pub struct RamFlash<const N: usize, const PAGE: usize> {
    bytes: &'static mut [u8; N],
}

impl<const N: usize, const PAGE: usize> RamFlash<N, PAGE> {
    /// The region, erased.
    pub fn new(bytes: &'static mut [u8; N]) -> Self {
        bytes.fill(0xFF);
        RamFlash { bytes }
    }

    /// The region's bytes (to dump them).
    pub fn bytes(&self) -> &[u8] {
        self.bytes.as_slice()
    }

    fn range(&mut self, offset: u32, len: usize) -> Result<&mut [u8], OutOfRange> {
        let at = offset as usize;
        self.bytes
            .get_mut(at..at.saturating_add(len))
            .ok_or(OutOfRange)
    }
}

impl<const N: usize, const PAGE: usize> ErrorType for RamFlash<N, PAGE> {
    type Error = OutOfRange;
}

impl<const N: usize, const PAGE: usize> ReadNorFlash for RamFlash<N, PAGE> {
    const READ_SIZE: usize = 1;

    async fn read(&mut self, offset: u32, out: &mut [u8]) -> Result<(), OutOfRange> {
        out.copy_from_slice(self.range(offset, out.len())?);
        Ok(())
    }

    fn capacity(&self) -> usize {
        N
    }
}

impl<const N: usize, const PAGE: usize> NorFlash for RamFlash<N, PAGE> {
    const WRITE_SIZE: usize = 4;
    const ERASE_SIZE: usize = PAGE;

    async fn erase(&mut self, from: u32, to: u32) -> Result<(), OutOfRange> {
        let len = (to as usize).saturating_sub(from as usize);
        self.range(from, len)?.fill(0xFF);
        Ok(())
    }

    async fn write(&mut self, offset: u32, data: &[u8]) -> Result<(), OutOfRange> {
        for (b, new) in self.range(offset, data.len())?.iter_mut().zip(data) {
            *b &= new;
        }
        Ok(())
    }
}
