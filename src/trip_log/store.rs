//! Trip records in flash: `sequential-storage`'s queue over any `embedded-storage-async`
//! `NorFlash` (a blocking part's driver goes through an adapter such as
//! `embassy-embedded-hal`'s `BlockingAsync`). Its items carry a CRC and a write cut by a power
//! loss is found and repaired on the next operation, so a record is whole or absent; when the
//! region is full the oldest page of records is erased for the new one. The calls block until
//! the flash is done (`embassy_futures::block_on`): the lowest-priority context makes them.

use core::ops::Range;
use embedded_storage_async::nor_flash::NorFlash;
use sequential_storage::cache::{Cache, Uncached};
use sequential_storage::queue::{QueueConfig, QueueStorage};

/// No cache: the queue reads page states from flash (a trip is rare; RAM is not).
type NoCache = Cache<Uncached, Uncached, Uncached>;

/// Why the store failed.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum StoreError {
    /// The flash range is not whole erase pages, or too small.
    Range,
    /// A record larger than a page.
    TooBig,
    /// The flash driver failed (a power cut, in the power-loss test).
    Flash,
    /// The queue found corruption it could not repair.
    Corrupted,
    /// A buffer too small for the record read.
    Buffer,
}

fn error<E>(e: sequential_storage::Error<E>) -> StoreError {
    match e {
        sequential_storage::Error::Storage { .. } => StoreError::Flash,
        sequential_storage::Error::ItemTooBig => StoreError::TooBig,
        sequential_storage::Error::BufferTooSmall(_) => StoreError::Buffer,
        _ => StoreError::Corrupted,
    }
}

/// The trip log's flash region.
pub struct Store<S: NorFlash> {
    queue: QueueStorage<S, NoCache>,
}

impl<S: NorFlash> Store<S> {
    /// The store over `range` of `flash` (whole erase pages, at least two).
    pub fn new(flash: S, range: Range<u32>) -> Result<Self, StoreError> {
        if range.end.saturating_sub(range.start) < 2 * S::ERASE_SIZE as u32 {
            return Err(StoreError::Range);
        }
        let config = QueueConfig::try_new(range).map_err(|_| StoreError::Range)?;
        Ok(Store {
            queue: QueueStorage::new(flash, config, Cache::new_uncached()),
        })
    }

    /// Appends a record; the oldest go when the region is full.
    pub fn push(&mut self, record: &[u8]) -> Result<(), StoreError> {
        embassy_futures::block_on(self.queue.push(record, true)).map_err(error)
    }

    /// Calls `f` on every stored record, oldest first, read into `buf`; returns how many.
    pub fn for_each(
        &mut self,
        buf: &mut [u8],
        mut f: impl FnMut(&[u8]),
    ) -> Result<usize, StoreError> {
        embassy_futures::block_on(async {
            let mut iter = self.queue.iter().await.map_err(error)?;
            let mut n = 0;
            while let Some(entry) = iter.next(buf).await.map_err(error)? {
                f(&entry);
                n += 1;
            }
            Ok(n)
        })
    }

    /// The flash back (e.g. to dump it).
    pub fn into_flash(self) -> S {
        self.queue.destroy().0
    }
}
