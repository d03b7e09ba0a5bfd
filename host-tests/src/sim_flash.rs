//! A NOR flash in RAM that can lose power mid-operation: the power-loss test's part. Like a
//! real NOR part, programming only clears bits and an erase sets a page to 0xFF. Every word
//! programmed and every page erased is one step; when the steps left run out the operation
//! stops where it is (a word not yet programmed stays as it was; a page being erased is left
//! half erased) and every later operation fails until power returns ([`SimFlash::power_on`]).

use embedded_storage_async::nor_flash::{
    ErrorType, NorFlash, NorFlashError, NorFlashErrorKind, ReadNorFlash,
};

/// Program unit (bytes): the STM32F4's 32-bit parallelism.
pub const WORD: usize = 4;
/// The STM32F405's smallest erase unit (bytes): sectors 0–3 of 16 KB (RM0090 Table 5).
pub const F405_SECTOR: usize = 16 * 1024;

/// The flash lost power.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct PowerLost;

impl NorFlashError for PowerLost {
    fn kind(&self) -> NorFlashErrorKind {
        NorFlashErrorKind::Other
    }
}

/// The flash (erase pages of `PAGE` bytes): its bytes, the steps taken, and an optional cut.
#[derive(Clone, Debug)]
pub struct SimFlash<const PAGE: usize> {
    /// The contents.
    pub bytes: Vec<u8>,
    /// Word programs and page erases so far.
    pub steps: u64,
    /// Word programs so far.
    pub words_written: u64,
    /// Page erases so far.
    pub erases: u64,
    /// Power is cut when `steps` reaches this.
    pub cut_at: Option<u64>,
    off: bool,
}

impl<const PAGE: usize> SimFlash<PAGE> {
    /// `pages` erased pages.
    pub fn new(pages: usize) -> Self {
        SimFlash::from_bytes(vec![0xFF; pages * PAGE])
    }

    /// A flash holding `bytes` (a dump).
    pub fn from_bytes(bytes: Vec<u8>) -> Self {
        SimFlash {
            bytes,
            steps: 0,
            words_written: 0,
            erases: 0,
            cut_at: None,
            off: false,
        }
    }

    /// Power back on, no cut pending.
    pub fn power_on(&mut self) {
        self.off = false;
        self.cut_at = None;
    }

    /// One step: fails (and stays off) once the cut is reached.
    fn step(&mut self) -> Result<(), PowerLost> {
        if self.off || self.cut_at.is_some_and(|c| self.steps >= c) {
            self.off = true;
            return Err(PowerLost);
        }
        self.steps += 1;
        Ok(())
    }
}

impl<const PAGE: usize> ErrorType for SimFlash<PAGE> {
    type Error = PowerLost;
}

impl<const PAGE: usize> ReadNorFlash for SimFlash<PAGE> {
    const READ_SIZE: usize = 1;

    async fn read(&mut self, offset: u32, out: &mut [u8]) -> Result<(), PowerLost> {
        if self.off {
            return Err(PowerLost);
        }
        let at = offset as usize;
        out.copy_from_slice(&self.bytes[at..at + out.len()]);
        Ok(())
    }

    fn capacity(&self) -> usize {
        self.bytes.len()
    }
}

impl<const PAGE: usize> NorFlash for SimFlash<PAGE> {
    const WRITE_SIZE: usize = WORD;
    const ERASE_SIZE: usize = PAGE;

    async fn erase(&mut self, from: u32, to: u32) -> Result<(), PowerLost> {
        for page in (from as usize..to as usize).step_by(PAGE) {
            if let Err(e) = self.step() {
                // Cut mid-erase: the first half of the page erased, the rest as it was.
                self.bytes[page..page + PAGE / 2].fill(0xFF);
                return Err(e);
            }
            self.bytes[page..page + PAGE].fill(0xFF);
            self.erases += 1;
        }
        Ok(())
    }

    async fn write(&mut self, offset: u32, data: &[u8]) -> Result<(), PowerLost> {
        for (k, word) in data.chunks(WORD).enumerate() {
            self.step()?;
            let at = offset as usize + k * WORD;
            for (b, new) in self.bytes[at..at + word.len()].iter_mut().zip(word) {
                *b &= new; // programming only clears bits
            }
            self.words_written += 1;
        }
        Ok(())
    }
}
