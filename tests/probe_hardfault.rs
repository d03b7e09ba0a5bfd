//! Fault probe: a permanently undefined instruction must HardFault and exit with code 102.
#![cfg_attr(target_os = "none", no_std, no_main)]
mod probe;
probe!("hardfault", cortex_m::asm::udf());
