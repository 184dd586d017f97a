//! Every link in the README and the guides stays inside the repository and resolves:
//! the file exists, and a `#section` names a heading of the Markdown file it points to.

use std::collections::HashSet;
use std::path::{Path, PathBuf};

fn root() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

/// The pages checked: the top-level Markdown files and every page under docs/.
fn pages() -> Vec<PathBuf> {
    let mut pages: Vec<PathBuf> = ["README.md", "ARCHITECTURE.md", "CHANGELOG.md"]
        .iter()
        .map(|p| root().join(p))
        .collect();
    let mut docs: Vec<PathBuf> = std::fs::read_dir(root().join("docs"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "md"))
        .collect();
    docs.sort();
    pages.extend(docs);
    pages
}

/// The lines of `text` outside fenced code blocks, with their numbers, inline code
/// removed.
fn prose(text: &str) -> Vec<(usize, String)> {
    let mut fenced = false;
    let mut out = Vec::new();
    for (i, line) in text.lines().enumerate() {
        if line.trim_start().starts_with("```") {
            fenced = !fenced;
            continue;
        }
        if !fenced {
            let mut kept = String::new();
            for (j, part) in line.split('`').enumerate() {
                if j % 2 == 0 {
                    kept.push_str(part);
                }
            }
            out.push((i + 1, kept));
        }
    }
    out
}

/// The targets of `[text](target)` and `![alt](target)` in a line.
fn targets(line: &str) -> Vec<String> {
    let mut out = Vec::new();
    let mut rest = line;
    while let Some(at) = rest.find("](") {
        let after = &rest[at + 2..];
        let Some(end) = after.find(')') else { break };
        out.push(after[..end].to_string());
        rest = &after[end..];
    }
    out
}

/// GitHub's anchor of a heading: lower case, punctuation dropped but `-` and `_`,
/// spaces as `-`.
fn anchor(heading: &str) -> String {
    heading
        .trim()
        .to_lowercase()
        .chars()
        .filter(|c| c.is_alphanumeric() || matches!(c, '-' | '_' | ' '))
        .map(|c| if c == ' ' { '-' } else { c })
        .collect()
}

fn anchors(page: &Path) -> HashSet<String> {
    let text = std::fs::read_to_string(page).unwrap();
    prose(&text)
        .into_iter()
        .filter_map(|(_, line)| {
            let hashes = line.chars().take_while(|&c| c == '#').count();
            (hashes > 0 && line[hashes..].starts_with(' ')).then(|| anchor(&line[hashes..]))
        })
        .collect()
}

#[test]
fn every_link_of_the_docs_resolves_within_the_repository() {
    let mut broken = Vec::new();
    let mut checked = 0;
    for page in pages() {
        let text = std::fs::read_to_string(&page).unwrap();
        let name = page.strip_prefix(root()).unwrap().display().to_string();
        for (n, line) in prose(&text) {
            for target in targets(&line) {
                checked += 1;
                if target.contains("://") || target.starts_with("mailto:") {
                    broken.push(format!(
                        "{name}:{n}: links outside the repository: {target}"
                    ));
                    continue;
                }
                let (path, section) = target.split_once('#').unwrap_or((&target, ""));
                let file = if path.is_empty() {
                    page.clone()
                } else {
                    page.parent().unwrap().join(path)
                };
                if !file.exists() {
                    broken.push(format!("{name}:{n}: no such file: {target}"));
                } else if !section.is_empty()
                    && file.extension().is_some_and(|e| e == "md")
                    && !anchors(&file).contains(section)
                {
                    broken.push(format!("{name}:{n}: no such section: {target}"));
                }
            }
        }
    }
    assert!(checked > 0, "no link found: the scan is broken");
    assert!(broken.is_empty(), "broken links:\n{}", broken.join("\n"));
}

#[test]
fn anchors_follow_githubs_rule() {
    assert_eq!(
        anchor(" The monitor, stage by stage"),
        "the-monitor-stage-by-stage"
    );
    assert_eq!(anchor(" `float::Auto` (kind 6)"), "floatauto-kind-6");
    assert_eq!(
        targets("see [a](x.md) and ![b](y.svg#z)"),
        ["x.md", "y.svg#z"]
    );
}
