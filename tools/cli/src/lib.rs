//! The logic of `misalign`'s host tools, behind the examples a user runs:
//! [`estimate`] is `cargo run --example estimate` (the CSV estimator and its
//! `--solve` inverses), `monitor` (feature `monitor`, on by default) is
//! `cargo run --example monitor`, [`monitor_input`] reads its scene and trace files and
//! [`monitor_output`] writes its event and threshold files (the Python package's replay
//! and planner give the same cells), [`svg`] makes figures any renderer draws alike;
//! [`table`] holds the rules both tools read their
//! files by. The examples are thin `main`s over it; the tests, the host benchmark and
//! the fuzz targets call the same functions in-process.

pub mod estimate;
#[cfg(feature = "monitor")]
pub mod monitor;
pub mod monitor_input;
pub mod monitor_output;
pub mod prepare;
pub mod reference_core;
pub mod replay;
pub mod svg;
pub mod table;
