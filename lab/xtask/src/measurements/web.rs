//! The web console's table (docs/web.csv, `cargo xtask web --measure`) and its
//! targets: what a browser downloads, the time to a usable page, the page's replay
//! rate against the monitor example's.

use crate::records::WebRow;
use std::fmt::Write as _;

/// The largest compressed download the page may take (B): wasm and script.
pub const DOWNLOAD_TARGET: u64 = 1 << 20;
/// The time to a usable page from the loopback the page must beat (ms).
pub const READY_TARGET_MS: f64 = 1000.0;
/// The share of the monitor example's rate the page's replay must reach.
pub const RATE_TARGET: f64 = 0.5;

/// The table, each figure against its target.
pub fn table(rows: &[WebRow]) -> Result<String, String> {
    let get = |q: &str| {
        rows.iter()
            .find(|r| r.quantity == q)
            .map(|r| r.value)
            .ok_or_else(|| format!("docs/web.csv: no {q}"))
    };
    let (wasm, script) = (get("download_wasm_gzip")?, get("download_script_gzip")?);
    let (ready, n) = (get("ready")?, get("replay_rows")?);
    let (page, example) = (get("replay_page")?, get("replay_example")?);
    let (pause, idle) = (get("replay_longest_pause")?, get("idle_longest_pause")?);
    let kib = |b: f64| format!("{:.0} KiB", b / 1024.0);
    let met = |ok: bool| if ok { "met" } else { "**missed**" };
    let total = wasm + script;
    let ratio = page / example;
    let mut s = String::from("| quantity | measured | target |\n|---|--:|---|\n");
    writeln!(s, "| download, gzip: the WebAssembly | {} | |", kib(wasm)).unwrap();
    writeln!(
        s,
        "| download, gzip: script, style and page | {} | |",
        kib(script)
    )
    .unwrap();
    writeln!(
        s,
        "| download, gzip: in all | {} | at most {}: {} |",
        kib(total),
        kib(DOWNLOAD_TARGET as f64),
        met(total <= DOWNLOAD_TARGET as f64)
    )
    .unwrap();
    writeln!(
        s,
        "| time to a usable page from the loopback (median of 5 cold loads) | {ready:.0} ms | under {READY_TARGET_MS:.0} ms: {} |",
        met(ready < READY_TARGET_MS)
    )
    .unwrap();
    writeln!(
        s,
        "| a {n:.0}-row trace replayed in the page (its worker, both passes) | {:.2} M rows/s | |",
        page / 1e6
    )
    .unwrap();
    writeln!(
        s,
        "| the same trace through the monitor example, same run | {:.2} M rows/s | |",
        example / 1e6
    )
    .unwrap();
    writeln!(
        s,
        "| the page's rate over the example's | {ratio:.2} | at least {RATE_TARGET}: {} |",
        met(ratio >= RATE_TARGET)
    )
    .unwrap();
    writeln!(
        s,
        "| the page's longest pause meanwhile (its own thread; idle for as long: {idle:.0} ms) | {pause:.0} ms | |"
    )
    .unwrap();
    Ok(s)
}
