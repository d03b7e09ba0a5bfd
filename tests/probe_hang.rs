//! Fault probe: a hang must be ended by the runner's timeout with exit code 124.
#![cfg_attr(target_os = "none", no_std, no_main)]
mod probe;
probe!(
    "hang",
    loop {
        cortex_m::asm::nop();
    }
);
