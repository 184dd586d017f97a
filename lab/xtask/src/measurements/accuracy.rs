//! The accuracy table (docs/accuracy.csv).

use crate::records::AccuracyRow;
use std::fmt::Write as _;

/// The quantities, in the table's order: `(CSV and reference column, table header)`.
pub const QUANTITIES: [(&str, &str); 8] = [
    ("s", "d/b"),
    ("F", "F"),
    ("phi0", "phi0"),
    ("m", "m"),
    ("n", "n"),
    ("a", "a"),
    ("b", "b"),
    ("p0", "p0"),
];

/// The table: a row per model and contact, a column per quantity.
pub fn table(rows: &[AccuracyRow]) -> String {
    let mut s = String::from("| model | contact | rows |");
    for (_, header) in QUANTITIES {
        write!(s, " {header} |").unwrap();
    }
    s.push_str("\n|---|---|--:|");
    s.push_str(&"--:|".repeat(QUANTITIES.len()));
    s.push('\n');
    let mut seen: Vec<(&str, &str)> = Vec::new();
    for r in rows {
        let key = (r.model.as_str(), r.contact.as_str());
        if seen.contains(&key) {
            continue;
        }
        seen.push(key);
        write!(s, "| {} | {} | {} |", r.model, r.contact, r.rows).unwrap();
        for (q, _) in QUANTITIES {
            let e = rows
                .iter()
                .find(|x| (x.model.as_str(), x.contact.as_str()) == key && x.quantity == q);
            match e {
                Some(x) => write!(s, " {:.1e} |", x.max_rel).unwrap(),
                None => s.push_str(" |"),
            }
        }
        s.push('\n');
    }
    s
}
