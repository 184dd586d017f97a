//! `cargo run --release --example monitor`: the condition monitor on the PC, replaying
//! the built-in scenario or a recorded trace (`-- --help` says how; the logic is
//! `misalign_cli::monitor`).

use std::io::IsTerminal;

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let progress = std::io::stderr().is_terminal();
    let code = misalign_cli::monitor::run(
        &args,
        &mut std::io::stdout().lock(),
        &mut std::io::stderr(),
        progress,
    );
    std::process::exit(code);
}
