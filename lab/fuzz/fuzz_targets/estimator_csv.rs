//! The CSV estimator on arbitrary bytes: any model, any contact, forward or either
//! inverse (`--solve mu|phi`); it must never panic, and it exits non-zero only for input
//! without a usable header (1).
#![no_main]

use misalign_cli::estimate as cli;

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let Some((&selector, input)) = data.split_first() else { return };
    let model = ["reference", "f32", "fixed"][(selector % 3) as usize];
    let contact = ["auto", "elliptic", "line"][((selector / 3) % 3) as usize];
    let solve = [None, Some("mu"), Some("phi")][((selector / 9) % 3) as usize];
    let mut args: Vec<String> = ["--model", model, "--contact", contact].iter().map(|s| s.to_string()).collect();
    if let Some(unknown) = solve {
        args.extend(["--solve".to_string(), unknown.to_string()]);
    }
    let (mut out, mut err) = (Vec::new(), Vec::new());
    let code = cli::run(&args, input, &mut out, &mut err);
    assert!(code == 0 || code == 1, "exit code {code}");
    if code == 0 {
        // One header for every model and contact; every row has its fields.
        let mut reader = csv::Reader::from_reader(&out[..]);
        let header = reader.headers().expect("a header").clone();
        assert!(header.iter().next() == Some(solve.unwrap_or("theta")));
        for row in reader.records() {
            assert_eq!(row.expect("the estimator writes CSV").len(), header.len());
        }
    }
});
