//! The table shapes' table (docs/shapes.csv), with their Pareto fronts.

use crate::figures::fronts;
use crate::records::ShapeRow;
use std::fmt::Write as _;

/// Per core and table, by instructions: the library's kernel, the shipped shape and
/// the shapes on either Pareto front (within the library's bytes, at any size), as
/// Markdown (docs/measurements.md).
pub fn table(rows: &[ShapeRow]) -> String {
    let mut s = String::new();
    writeln!(
        s,
        "| cpu | table | shape | instructions mean / max | bytes | max relative error | front within the library's bytes | front at any size |"
    )
    .unwrap();
    writeln!(s, "|---|---|---|--:|--:|--:|---|---|").unwrap();
    let mut panels: Vec<(&str, &str)> = Vec::new();
    for r in rows {
        if !panels.contains(&(r.cpu.as_str(), r.table.as_str())) {
            panels.push((&r.cpu, &r.table));
        }
    }
    for (cpu, table) in panels {
        let mut panel: Vec<&ShapeRow> = rows
            .iter()
            .filter(|r| r.cpu == cpu && r.table == table)
            .collect();
        let f = fronts(&panel);
        let on = |front: &[&ShapeRow], r: &ShapeRow| front.iter().any(|x| std::ptr::eq(*x, r));
        panel.sort_by(|a, b| a.mean.total_cmp(&b.mean));
        for r in panel {
            let (within, any) = (on(&f.within, r), on(&f.any, r));
            if r.kind == "variant" && !within && !any {
                continue;
            }
            let name = match r.kind.as_str() {
                "library" => "library's kernel".to_string(),
                "shipped" => format!("{} (shipped)", r.shape),
                _ => r.shape.clone(),
            };
            let yes = |b: bool| if b { "yes" } else { "" };
            writeln!(
                s,
                "| {cpu} | {table} | {name} | {} / {} | {} | {:.2e} | {} | {} |",
                r.mean,
                r.max,
                r.bytes,
                r.error,
                yes(within),
                yes(any)
            )
            .unwrap();
        }
    }
    s
}
