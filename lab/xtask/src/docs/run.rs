//! Running a block as a reader would (from the repository's root) and comparing what
//! a command prints with the text a page shows of it.

use super::blocks::{Block, How};
use std::path::Path;
use std::process::{Command, Stdio};
use std::time::Instant;

/// What a command did.
pub struct Ran {
    pub ok: bool,
    pub stdout: String,
    pub stderr: String,
    pub seconds: f64,
}

/// Environment that `cargo xtask` itself sets and a reader's shell does not have.
fn clean(cmd: &mut Command) -> &mut Command {
    for (key, _) in std::env::vars_os() {
        let key = key.to_string_lossy().into_owned();
        let cargo_run = key == "CARGO"
            || key.starts_with("CARGO_PKG_")
            || matches!(
                key.as_str(),
                "CARGO_MANIFEST_DIR"
                    | "CARGO_MANIFEST_PATH"
                    | "CARGO_CRATE_NAME"
                    | "CARGO_BIN_NAME"
                    | "CARGO_PRIMARY_PACKAGE"
                    | "MISALIGN_QEMU_MACHINE"
            );
        if cargo_run {
            cmd.env_remove(&key);
        }
    }
    cmd
}

/// Runs `program args...` from `root` with no input.
fn run(root: &Path, program: &str, args: &[&str]) -> Ran {
    let start = Instant::now();
    let out = clean(
        Command::new(program)
            .args(args)
            .current_dir(root)
            .stdin(Stdio::null()),
    )
    .output();
    let seconds = start.elapsed().as_secs_f64();
    match out {
        Ok(o) => Ran {
            ok: o.status.success(),
            stdout: String::from_utf8_lossy(&o.stdout).into_owned(),
            stderr: String::from_utf8_lossy(&o.stderr).into_owned(),
            seconds,
        },
        Err(e) => Ran {
            ok: false,
            stdout: String::new(),
            stderr: format!("cannot run {program}: {e}"),
            seconds,
        },
    }
}

/// A shell script, as bash runs it with `-e -o pipefail`.
pub fn shell(root: &Path, script: &str) -> Ran {
    run(root, "bash", &["-e", "-o", "pipefail", "-c", script])
}

/// A Python block, with `python`, from a file beside the target directory.
pub fn python(root: &Path, python: &str, code: &str, tag: &str) -> Ran {
    let dir = root.join("target/docs");
    let file = dir.join(format!("{tag}.py"));
    if let Err(e) = std::fs::create_dir_all(&dir).and_then(|()| std::fs::write(&file, code)) {
        return Ran {
            ok: false,
            stdout: String::new(),
            stderr: format!("{}: {e}", file.display()),
            seconds: 0.0,
        };
    }
    run(root, python, &[&file.to_string_lossy()])
}

/// Untracked files (not ignored) under `root`, as git lists them.
pub fn untracked(root: &Path) -> Vec<String> {
    run(root, "git", &["ls-files", "--others", "--exclude-standard"])
        .stdout
        .lines()
        .map(str::to_string)
        .collect()
}

/// The lines of `text`, trailing blanks removed, trailing empty lines dropped.
pub fn lines(text: &str) -> Vec<&str> {
    let mut v: Vec<&str> = text.lines().map(str::trim_end).collect();
    while v.last().is_some_and(|l| l.is_empty()) {
        v.pop();
    }
    v
}

/// An extract's line: the text it must match and whether that is only the start of
/// the output's line (`...` at its end).
fn extract_line(line: &str) -> (&str, bool) {
    match line.trim_end().strip_suffix("...") {
        Some(stem) => (stem.trim_end(), true),
        None => (line.trim_end(), false),
    }
}

/// Whether `out` is what `stem` (with `prefix`) shows.
fn matches(out: &str, stem: &str, prefix: bool) -> bool {
    if prefix {
        out.starts_with(stem)
    } else {
        out == stem
    }
}

/// The output line after `from` most like `stem`: the longest common start.
fn closest<'a>(output: &[&'a str], from: usize, stem: &str) -> Option<&'a str> {
    output.get(from..)?.iter().copied().max_by_key(|o| {
        o.chars()
            .zip(stem.chars())
            .take_while(|(a, b)| a == b)
            .count()
    })
}

/// Checks an extract against `output`; on a mismatch, the extract as `output` would
/// write it (each line that differs replaced by the output's line most like it) and
/// what differs.
pub fn extract(shown: &[String], output: &str) -> Result<(), (Vec<String>, Vec<String>)> {
    let out = lines(output);
    let mut at = 0;
    let mut fixed = Vec::new();
    let mut differ = Vec::new();
    for line in shown {
        if line.trim() == "..." || line.trim().is_empty() {
            fixed.push(line.clone());
            continue;
        }
        let (stem, prefix) = extract_line(line);
        if let Some(j) = out[at.min(out.len())..]
            .iter()
            .position(|o| matches(o, stem, prefix))
        {
            at += j + 1;
            fixed.push(line.clone());
            continue;
        }
        match closest(&out, at, stem) {
            Some(near) => {
                let new = if prefix {
                    let cut: String = near.chars().take(stem.chars().count()).collect();
                    format!("{cut}{}", &line[stem.len()..])
                } else {
                    near.to_string()
                };
                differ.push(format!("shown:   {line}\n    printed: {near}"));
                if let Some(j) = out[at..].iter().position(|o| *o == near) {
                    at += j + 1;
                }
                fixed.push(new);
            }
            None => {
                differ.push(format!(
                    "shown:   {line}\n    printed: nothing after the lines above"
                ));
                fixed.push(line.clone());
            }
        }
    }
    if differ.is_empty() {
        Ok(())
    } else {
        Err((fixed, differ))
    }
}

/// The `$ command` lines of a transcript (continuations joined) with the output shown
/// after each.
pub fn transcript(body: &[String]) -> Vec<(Vec<String>, Vec<String>)> {
    let mut steps: Vec<(Vec<String>, Vec<String>)> = Vec::new();
    let mut continued = false;
    for line in body {
        if let Some(command) = line.strip_prefix("$ ") {
            steps.push((vec![command.to_string()], Vec::new()));
            continued = command.trim_end().ends_with('\\');
        } else if let Some(step) = steps.last_mut() {
            if continued {
                step.0.push(line.clone());
                continued = line.trim_end().ends_with('\\');
            } else {
                step.1.push(line.clone());
            }
        }
    }
    for step in &mut steps {
        while step.1.last().is_some_and(|l| l.trim().is_empty()) {
            step.1.pop();
        }
    }
    steps
}

/// The script `how` runs for `block`: its text with the substitutions made.
pub fn script(block: &Block, how: &How) -> String {
    let mut text = block.text();
    if let How::Run { replace, .. } = how {
        for (from, to) in replace {
            text = text.replace(from.as_str(), to);
        }
    }
    text
}

/// The last `n` lines of `text`.
pub fn tail(text: &str, n: usize) -> String {
    let v: Vec<&str> = text.lines().collect();
    v[v.len().saturating_sub(n)..].join("\n")
}

#[cfg(test)]
mod tests {
    use super::*;

    fn own(v: &[&str]) -> Vec<String> {
        v.iter().map(|s| s.to_string()).collect()
    }

    #[test]
    fn an_extract_is_lines_of_the_output_in_order() {
        let output = "a 1\nb 2\nc 3 and more\nd 4\n";
        assert!(extract(&own(&["a 1", "...", "c 3 ...", "d 4"]), output).is_ok());
        assert!(extract(&own(&["b 2", "d 4"]), output).is_ok());
        // Out of order, a figure that drifted, a prefix that is not one.
        assert!(extract(&own(&["d 4", "a 1"]), output).is_err());
        let (fixed, differ) = extract(&own(&["a 1", "c 3 ...", "d 5"]), output).unwrap_err();
        assert_eq!(fixed, own(&["a 1", "c 3 ...", "d 4"]));
        assert_eq!(differ.len(), 1);
        let (fixed, _) = extract(&own(&["c 4 ..."]), output).unwrap_err();
        assert_eq!(fixed, own(&["c 3 ..."]));
    }

    #[test]
    fn a_transcript_is_commands_and_their_output() {
        let body = own(&["$ printf 'a\\n' \\", "    | cat", "a", "", "$ true", ""]);
        let steps = transcript(&body);
        assert_eq!(steps.len(), 2);
        assert_eq!(steps[0].0, own(&["printf 'a\\n' \\", "    | cat"]));
        assert_eq!(steps[0].1, own(&["a"]));
        assert!(steps[1].1.is_empty());
    }
}
