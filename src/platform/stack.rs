//! Stack high-water mark: cortex-m-rt's `paint-stack` fills the stack with `0xCCCC_CCCC` at
//! reset; the deepest word no longer holding the paint marks the most stack ever used.

/// The paint value (cortex-m-rt's `STACK_PAINT_VALUE`).
const PAINT: u32 = 0xCCCC_CCCC;

extern "C" {
    static _stack_start: u32;
    static _stack_end: u32;
}

/// Bytes of stack used so far (deepest point), by scanning up from the stack's lowest address.
#[allow(unsafe_code)]
pub fn high_water_bytes() -> u32 {
    // The linker script defines both symbols as 4-aligned addresses bounding the stack region
    // in RAM (`_stack_end <= _stack_start`); only their addresses are taken.
    let (bottom, top) = (
        core::ptr::addr_of!(_stack_end) as usize,
        core::ptr::addr_of!(_stack_start) as usize,
    );
    let mut addr = bottom;
    while addr < top {
        // SAFETY: `addr` is 4-aligned and within [_stack_end, _stack_start), RAM that is live
        // but unknown to the compiler, hence the volatile read.
        let word = unsafe { core::ptr::read_volatile(addr as *const u32) };
        if word != PAINT {
            break;
        }
        addr += 4;
    }
    (top - addr) as u32
}
