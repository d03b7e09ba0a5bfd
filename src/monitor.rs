//! The monitor: the 10 kHz fixed-point reduced model that estimates pressing force and braking
//! torque and flags brake failure. (Being built under issue 4.)
