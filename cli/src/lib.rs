//! The logic of `misalign`'s host tools, behind the examples a user runs:
//! [`estimate`] is `cargo run --example estimate` (the CSV estimator and its
//! `--solve` inverses), [`monitor_input`] reads the scene and trace files of
//! `cargo run --example monitor`. The examples are thin `main`s over it; the tests, the
//! host benchmark and the fuzz targets call the same functions in-process.

pub mod estimate;
pub mod monitor_events;
pub mod monitor_input;
