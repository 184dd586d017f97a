//! CSV estimator for engineers: one row of scene and sample in, one row of results
//! out. `cargo run --release --example estimate -- --help` says how.

use misalign_cli::estimate as cli;

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let stdin = std::io::stdin();
    let stdout = std::io::stdout();
    let code = cli::run(&args, stdin.lock(), stdout.lock(), &mut std::io::stderr());
    std::process::exit(code);
}
