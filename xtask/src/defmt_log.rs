//! Decoding the defmt byte stream QEMU writes to stdout (semihosting) into readable lines.
//!
//! The `defmt-decoder` crate does the work inside the xtask, so no `defmt-print` needs
//! installing. [`LogTable`] owns what the ELF says (format strings, source locations);
//! [`LogDecoder`] borrows it for one run and turns bytes into lines as they arrive.

use defmt_decoder::{DecodeError, Locations, StreamDecoder, Table};

/// The defmt table and source locations of one ELF image.
pub struct LogTable {
    table: Table,
    locations: Option<Locations>,
}

impl LogTable {
    /// Reads the defmt table from an ELF image.
    pub fn from_elf(elf: &[u8]) -> Result<LogTable, String> {
        let table = Table::parse(elf)
            .map_err(|e| format!("reading the defmt table: {e}"))?
            .ok_or("the ELF has no defmt table (was it built with -Tdefmt.x?)")?;
        let locations = table.get_locations(elf).ok().filter(|l| !l.is_empty());
        Ok(LogTable { table, locations })
    }

    /// A stream decoder over this table.
    pub fn decoder(&self) -> LogDecoder<'_> {
        LogDecoder {
            log: self,
            stream: self.table.new_stream_decoder(),
            malformed: 0,
        }
    }
}

/// Turns bytes into decoded log lines, frame by frame.
pub struct LogDecoder<'t> {
    log: &'t LogTable,
    stream: Box<dyn StreamDecoder + Send + Sync + 't>,
    /// Frames that could not be decoded (a sign of a corrupt stream).
    pub malformed: usize,
}

impl LogDecoder<'_> {
    /// Feeds received bytes; returns the lines decoded so far. Error frames carry their source
    /// location on a second line when the ELF has it.
    pub fn feed(&mut self, bytes: &[u8]) -> Vec<String> {
        self.stream.received(bytes);
        let mut lines = Vec::new();
        loop {
            match self.stream.decode() {
                Ok(frame) => {
                    let mut line = frame.display(false).to_string();
                    let is_error = frame.level().is_some_and(|l| format!("{l:?}") == "Error");
                    if is_error {
                        if let Some(loc) = self
                            .log
                            .locations
                            .as_ref()
                            .and_then(|l| l.get(&frame.index()))
                        {
                            line.push_str(&format!("\n└─ {}:{}", loc.file.display(), loc.line));
                        }
                    }
                    lines.push(line);
                }
                Err(DecodeError::UnexpectedEof) => break,
                Err(DecodeError::Malformed) => {
                    self.malformed += 1;
                    if !self.log.table.encoding().can_recover() {
                        break;
                    }
                }
            }
        }
        lines
    }
}
