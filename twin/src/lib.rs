//! The digital twin: the paper's full rotation–translation model in f64, host only.
//! (Being built under issue 3.)
