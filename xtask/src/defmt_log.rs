//! Decoding the defmt byte stream QEMU writes to stdout (semihosting) into readable lines.
//!
//! The `defmt-decoder` crate does the work inside the xtask, so no `defmt-print` needs
//! installing. Lines are printed as they are decoded and also kept for callers that check them.

use defmt_decoder::{DecodeError, Locations, Table};

/// Turns bytes into decoded log lines, frame by frame.
pub struct LogDecoder {
    table: &'static Table,
    locations: Option<Locations>,
    decoder: Box<dyn defmt_decoder::StreamDecoder + Send + Sync + 'static>,
    /// Bytes that could not be decoded (a sign of a corrupt stream).
    pub malformed: usize,
}

impl LogDecoder {
    /// Reads the defmt table from an ELF image.
    pub fn from_elf(elf: &[u8]) -> Result<LogDecoder, String> {
        let table = Table::parse(elf)
            .map_err(|e| format!("reading the defmt table: {e}"))?
            .ok_or("the ELF has no defmt table (was it built with -Tdefmt.x?)")?;
        let locations = table.get_locations(elf).ok().filter(|l| !l.is_empty());
        // The table must outlive the stream decoder that borrows it; one table per process run.
        let table: &'static Table = Box::leak(Box::new(table));
        Ok(LogDecoder {
            table,
            locations,
            decoder: table.new_stream_decoder(),
            malformed: 0,
        })
    }

    /// Feeds received bytes; returns the lines decoded so far.
    pub fn feed(&mut self, bytes: &[u8]) -> Vec<String> {
        self.decoder.received(bytes);
        let mut lines = Vec::new();
        loop {
            match self.decoder.decode() {
                Ok(frame) => {
                    let mut line = frame.display(false).to_string();
                    let is_error = frame.level().is_some_and(|l| format!("{l:?}") == "Error");
                    if is_error {
                        if let Some(loc) =
                            self.locations.as_ref().and_then(|l| l.get(&frame.index()))
                        {
                            line.push_str(&format!("\n└─ {}:{}", loc.file.display(), loc.line));
                        }
                    }
                    lines.push(line);
                }
                Err(DecodeError::UnexpectedEof) => break,
                Err(DecodeError::Malformed) => {
                    self.malformed += 1;
                    if !self.table.encoding().can_recover() {
                        break;
                    }
                }
            }
        }
        lines
    }
}
