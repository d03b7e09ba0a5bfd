//! The digital twin of the no-back brake: the paper's rotation–translation model in f64, host
//! only, with two readings (`paper` and `physical`, docs/model.md), an error-controlled stiff
//! integrator with event location, scenes, sensor traces and metrics.

pub mod args;
pub mod cli;
pub mod contact;
pub mod convergence;
pub mod fault;
pub mod friction;
pub mod metrics;
pub mod model;
pub mod pack;
pub mod paper_page;
pub mod paper_protocol;
pub mod paper_table;
pub mod ramp_friction;
pub mod reading;
pub mod scene;
pub mod scene_file;
pub mod sensing;
pub mod sim;
pub mod solver;
pub mod spring;
pub mod svg;
pub mod sweep;
pub mod trace;
