//! The PC side of a scene configured in the field: prepares a scene on the host and
//! writes it as bytes (`misalign::prepared`: versioned, with a CRC-32) for a node to
//! load with `from_bytes`, integer checks only, no floating-point preparation. The node
//! answers bit for bit as if it had prepared the scene itself.
//!
//! ```sh
//! # The demo rollers for the fixed-point core (1 mN and 10 prad per count):
//! cargo run --example prepare -- --type fixed-elliptic --out scene.bin 0.05 0.05 79.3e9 0.3 0.3
//! ```
//!
//! Prints the bytes in hex (and a Rust array with `--rust`); `--out` writes them raw.

use clap::Parser;
use misalign::Scene;
use misalign_cli::prepare::{self, Choice, Options, SceneType};
use std::process::ExitCode;

/// Prepare a scene on the host and write it as bytes for the node (`from_bytes`).
#[derive(Parser)]
struct Args {
    /// Radius R1 (m).
    r1: f64,
    /// Radius R2 (m; inf for a plane).
    r2: f64,
    /// Shear modulus G (Pa).
    g: f64,
    /// Poisson's ratio nu.
    nu: f64,
    /// Friction coefficient mu.
    mu: f64,
    /// The prepared scene type the node loads.
    #[arg(long, value_enum, default_value = "fixed-elliptic")]
    r#type: SceneType,
    /// Roller contact length (m), for section 9's choice and line contact's total load.
    #[arg(long)]
    length: Option<f64>,
    /// Model choice of the auto types.
    #[arg(long, value_enum, default_value = "section9")]
    choice: Choice,
    /// The fixed-point core's load LSB (N per count).
    #[arg(long, default_value_t = Options::default().load_lsb)]
    load_lsb: f64,
    /// The fixed-point core's angle LSB (rad per count).
    #[arg(long, default_value_t = Options::default().angle_lsb)]
    angle_lsb: f64,
    /// The d/b threshold of the risk flag.
    #[arg(long)]
    risk: Option<f32>,
    /// Write the bytes here (raw).
    #[arg(long)]
    out: Option<std::path::PathBuf>,
    /// Print a Rust array too, for a build script or a source file.
    #[arg(long)]
    rust: bool,
}

fn main() -> ExitCode {
    let args = Args::parse();
    match prepare(&args) {
        Ok(bytes) => {
            let hex: String = bytes.iter().map(|b| format!("{b:02x}")).collect();
            println!("{hex}");
            if args.rust {
                println!("[u8; {}] = {bytes:?}", bytes.len());
            }
            if let Some(path) = &args.out
                && let Err(e) = std::fs::write(path, &bytes)
            {
                eprintln!("prepare: cannot write {}: {e}", path.display());
                return ExitCode::FAILURE;
            }
            ExitCode::SUCCESS
        }
        Err(e) => {
            eprintln!("prepare: {e}");
            ExitCode::FAILURE
        }
    }
}

/// The scene prepared as `args` say, as bytes.
fn prepare(args: &Args) -> Result<Vec<u8>, misalign::Error> {
    let mut scene = Scene::new(args.r1, args.r2, args.g, args.nu, args.mu)?;
    if let Some(l) = args.length {
        scene = scene.with_length(l)?;
    }
    let options = Options {
        scene_type: args.r#type,
        choice: args.choice,
        load_lsb: args.load_lsb,
        angle_lsb: args.angle_lsb,
        risk: args.risk,
    };
    prepare::prepared(&scene, &options)
}
