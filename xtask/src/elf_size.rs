//! Flash and static-RAM use of a firmware ELF, read from its section headers.
//!
//! Flash holds every allocated section below RAM plus the load image of `.data`; static RAM is
//! every allocated section at or above `RAM_ORIGIN` (`.data`, `.bss`, `.uninit`). Stack is not
//! static and is measured separately (high-water mark) by the firmware.

use object::{Object, ObjectSection, SectionFlags};

/// Origin of RAM in `memory.x`.
const RAM_ORIGIN: u64 = 0x2000_0000;
/// ELF `SHF_ALLOC`.
const SHF_ALLOC: u64 = 0x2;
/// ELF `SHT_NOBITS` (occupies RAM, not flash).
const SHT_NOBITS: u32 = 8;

/// Bytes of flash and of static RAM an image needs.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Size {
    /// Flash bytes (code, read-only data, vector table, `.data` initialisers).
    pub flash_bytes: u64,
    /// Static RAM bytes (`.data`, `.bss`, `.uninit`).
    pub ram_bytes: u64,
}

/// Reads the sizes from an ELF file.
pub fn of_file(path: &str) -> Result<Size, String> {
    let bytes = std::fs::read(path).map_err(|e| format!("reading {path}: {e}"))?;
    let file = object::File::parse(&*bytes).map_err(|e| format!("parsing {path}: {e}"))?;
    let mut size = Size {
        flash_bytes: 0,
        ram_bytes: 0,
    };
    for section in file.sections() {
        let SectionFlags::Elf { sh_flags } = section.flags() else {
            continue;
        };
        if sh_flags & SHF_ALLOC == 0 || section.size() == 0 {
            continue;
        }
        let nobits = matches!(
            section.kind(),
            object::SectionKind::UninitializedData | object::SectionKind::UninitializedTls
        ) || elf_type(&section) == Some(SHT_NOBITS);
        if section.address() >= RAM_ORIGIN {
            size.ram_bytes += section.size();
            if !nobits {
                size.flash_bytes += section.size(); // initialiser stored in flash
            }
        } else {
            size.flash_bytes += section.size();
        }
    }
    Ok(size)
}

fn elf_type(section: &object::Section<'_, '_>) -> Option<u32> {
    match section.kind() {
        object::SectionKind::Elf(t) => Some(t),
        _ => None,
    }
}
