//! The CSV estimator on arbitrary bytes: any model, any contact; it must never panic,
//! and it exits non-zero only for input that is not CSV or lacks a column.
#![no_main]

#[path = "../../examples/estimate/cli.rs"]
#[allow(dead_code)]
mod cli;

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let Some((&selector, input)) = data.split_first() else { return };
    let model = ["reference", "f32", "fixed"][(selector % 3) as usize];
    let contact = ["elliptic", "line"][((selector / 3) % 2) as usize];
    let args: Vec<String> = ["--model", model, "--contact", contact].iter().map(|s| s.to_string()).collect();
    let (mut out, mut err) = (Vec::new(), Vec::new());
    let code = cli::run(&args, input, &mut out, &mut err);
    assert!(code == 0 || code == 1, "exit code {code}");
    if code == 0 {
        // Every output row has the same number of fields as the header.
        let text = String::from_utf8(out).expect("the estimator writes UTF-8");
        let mut lines = text.lines();
        if let Some(header) = lines.next() {
            assert!(header.starts_with("theta,") || header.starts_with("R,"));
        }
    }
});
