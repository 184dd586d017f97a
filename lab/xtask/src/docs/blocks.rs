//! The fenced blocks of the README and of every page under docs/, and how each is run:
//! by its info string, or by the annotation on the line above it (docs/README.md, "Every
//! block runs").

use std::path::Path;

/// One fenced block of a page.
#[derive(Debug, Clone)]
pub struct Block {
    /// The page, from the repository's root (`docs/firmware.md`).
    pub page: String,
    /// The line of the opening fence (1-based).
    pub line: usize,
    /// The info string (`sh`, `rust,ignore`, `text`, or empty).
    pub info: String,
    /// The lines between the fences, the fence's indentation removed.
    pub body: Vec<String>,
    /// The annotation on the line above the fence (`<!-- docs: ... -->`), its text.
    pub note: Option<String>,
}

impl Block {
    /// The language: the info string up to its first comma or space.
    pub fn lang(&self) -> &str {
        self.info.split([',', ' ']).next().unwrap_or("").trim()
    }

    /// `page:line`, as the check names a block.
    pub fn at(&self) -> String {
        format!("{}:{}", self.page, self.line)
    }

    pub fn text(&self) -> String {
        let mut s = self.body.join("\n");
        s.push('\n');
        s
    }
}

/// How a block is run, or why it is not.
#[derive(Debug, Clone, PartialEq)]
pub enum How {
    /// Rust on a page that `src/lib.rs` includes as doctests: `cargo test` runs it.
    Doctest,
    /// Run by the check from the repository's root (sh with bash, python with the
    /// `--python` interpreter), with these substitutions; the files it writes are
    /// checked to exist, then removed.
    Run {
        replace: Vec<(String, String)>,
        writes: Vec<String>,
    },
    /// Every command of the block is a command of `.ci/run`, which runs it as written.
    Ci,
    /// A named test runs it (`FILE::NAME`), with the fixture its note describes.
    Test { file: String, name: String },
    /// Text that is exactly what `command` prints on stdout.
    Output { command: String },
    /// Text whose lines are lines of what `command` prints, in order (`...` stands for
    /// lines left out; a line ending in `...` is the start of one).
    Extract { command: String },
    /// `$ command` lines, each followed by exactly what it prints.
    Transcript,
    /// A drawing: nothing to run.
    Drawing,
    /// The rare exception, listed by every run of the check with its reason.
    NotRun { reason: String },
}

impl How {
    /// A short name for the check's listing.
    pub fn name(&self) -> &'static str {
        match self {
            How::Doctest => "doctest",
            How::Run { .. } => "run",
            How::Ci => "ci",
            How::Test { .. } => "test",
            How::Output { .. } => "output",
            How::Extract { .. } => "extract",
            How::Transcript => "transcript",
            How::Drawing => "drawing",
            How::NotRun { .. } => "not run",
        }
    }
}

/// The pages checked: README.md and every `.md` under docs/, sorted.
pub fn pages(root: &Path) -> Result<Vec<String>, String> {
    fn walk(dir: &Path, root: &Path, out: &mut Vec<String>) -> Result<(), String> {
        let entries = std::fs::read_dir(dir).map_err(|e| format!("{}: {e}", dir.display()))?;
        for entry in entries {
            let path = entry.map_err(|e| e.to_string())?.path();
            if path.is_dir() {
                walk(&path, root, out)?;
            } else if path.extension().is_some_and(|e| e == "md") {
                let rel = path.strip_prefix(root).map_err(|e| e.to_string())?;
                out.push(rel.to_string_lossy().replace('\\', "/"));
            }
        }
        Ok(())
    }
    let mut out = vec!["README.md".to_string()];
    let mut docs = Vec::new();
    walk(&root.join("docs"), root, &mut docs)?;
    docs.sort();
    out.extend(docs);
    Ok(out)
}

/// The fenced blocks of `text` (the page `page`).
pub fn parse(page: &str, text: &str) -> Result<Vec<Block>, String> {
    let lines: Vec<&str> = text.lines().collect();
    let mut blocks = Vec::new();
    let mut i = 0;
    while i < lines.len() {
        let line = lines[i];
        let indent = line.len() - line.trim_start().len();
        let Some(info) = line.trim_start().strip_prefix("```") else {
            i += 1;
            continue;
        };
        let note = i
            .checked_sub(1)
            .map(|j| lines[j].trim())
            .and_then(|l| l.strip_prefix("<!-- docs:"))
            .and_then(|l| l.strip_suffix("-->"))
            .map(|n| n.trim().to_string());
        let start = i;
        let mut body = Vec::new();
        i += 1;
        loop {
            let Some(l) = lines.get(i) else {
                return Err(format!("{page}:{}: the block is never closed", start + 1));
            };
            if l.trim() == "```" {
                break;
            }
            let strip = l.len() - l.trim_start().len();
            body.push(l[strip.min(indent)..].to_string());
            i += 1;
        }
        blocks.push(Block {
            page: page.to_string(),
            line: start + 1,
            info: info.trim().to_string(),
            body,
            note,
        });
        i += 1;
    }
    Ok(blocks)
}

/// The text between the first pair of backticks of `s`, and what follows it.
fn backticked(s: &str) -> Option<(&str, &str)> {
    let rest = s.trim_start().strip_prefix('`')?;
    let end = rest.find('`')?;
    Some((&rest[..end], &rest[end + 1..]))
}

/// The strings of `replace "A" with "B"`.
fn replace_clause(s: &str) -> Option<(String, String)> {
    let rest = s.strip_prefix("replace \"")?;
    let (from, rest) = rest.split_once("\" with \"")?;
    let (to, tail) = rest.split_once('"')?;
    tail.trim()
        .is_empty()
        .then(|| (from.to_string(), to.to_string()))
}

/// How `note` (an annotation's text) says to run a block.
pub fn annotation(note: &str) -> Result<How, String> {
    let note = note.trim();
    // `output of `CMD``, `extract of `CMD``: the command, and nothing after it.
    let command = |rest: &str, what: &str| -> Result<String, String> {
        match backticked(rest) {
            Some((command, tail)) if tail.trim().is_empty() => Ok(command.to_string()),
            Some((_, tail)) => Err(format!("unexpected text after the command: `{tail}`")),
            None => Err(format!("`{what}` takes a `command`")),
        }
    };
    if let Some(rest) = note.strip_prefix("output of") {
        return Ok(How::Output {
            command: command(rest, "output of")?,
        });
    }
    if let Some(rest) = note.strip_prefix("extract of") {
        return Ok(How::Extract {
            command: command(rest, "extract of")?,
        });
    }
    if let Some(reason) = note.strip_prefix("not run:") {
        let reason = reason.trim();
        if reason.is_empty() {
            return Err("`not run:` needs its reason".into());
        }
        return Ok(How::NotRun {
            reason: reason.to_string(),
        });
    }
    if let Some(rest) = note.strip_prefix("test ") {
        let target = rest.split_whitespace().next().unwrap_or("");
        let (file, name) = target.split_once("::").ok_or(
            "`test` takes FILE::NAME (a file from the repository's root and a test in it)",
        )?;
        return Ok(How::Test {
            file: file.to_string(),
            name: name.to_string(),
        });
    }
    match note {
        "ci" => return Ok(How::Ci),
        "transcript" => return Ok(How::Transcript),
        "drawing" => return Ok(How::Drawing),
        _ => {}
    }
    let mut clauses = note.split(';').map(str::trim);
    if clauses.next() != Some("run") {
        return Err(format!("unknown annotation `{note}`"));
    }
    let (mut replace, mut writes) = (Vec::new(), Vec::new());
    for clause in clauses {
        if let Some(files) = clause.strip_prefix("writes ") {
            writes.extend(files.split_whitespace().map(str::to_string));
        } else if let Some(pair) = replace_clause(clause) {
            replace.push(pair);
        } else {
            return Err(format!(
                "unknown clause `{clause}` (writes FILE..., or replace \"A\" with \"B\")"
            ));
        }
    }
    Ok(How::Run { replace, writes })
}

/// Whether `src/lib.rs` includes `page` as doctests (`include_str!("../PAGE")`).
pub fn doctest_page(root: &Path, page: &str) -> bool {
    std::fs::read_to_string(root.join("src/lib.rs"))
        .is_ok_and(|lib| lib.contains(&format!("include_str!(\"../{page}\")")))
}

/// How `block` is run: its annotation, else what its language implies.
pub fn how(root: &Path, block: &Block) -> Result<How, String> {
    if let Some(note) = &block.note {
        return annotation(note);
    }
    let lang = block.lang();
    let attrs: Vec<&str> = block.info.split(',').map(str::trim).skip(1).collect();
    match lang {
        "rust" if attrs.contains(&"ignore") => Err(
            "`rust,ignore` is run by nothing: compile it (a doctest, `no_run` if it must not \
             run) or name the test that runs it"
                .into(),
        ),
        "rust" | "" if doctest_page(root, &block.page) => Ok(How::Doctest),
        "rust" => Err(format!(
            "a Rust block on a page no doctest includes (src/lib.rs: include_str!(\"../{}\"))",
            block.page
        )),
        "sh" | "bash" | "shell" | "python" => Ok(How::Run {
            replace: Vec::new(),
            writes: Vec::new(),
        }),
        "" => Err(
            "a block without a language: say what it is (```text, ```sh, ...) and annotate it"
                .into(),
        ),
        other => Err(format!(
            "a `{other}` block needs an annotation: output of `command`, extract of \
             `command`, transcript, drawing, test FILE::NAME or not run: REASON"
        )),
    }
}

/// The commands of a shell script: continuation lines joined, comments and blank
/// lines dropped, whitespace runs made one space.
pub fn commands(script: &str) -> Vec<String> {
    let mut out = Vec::new();
    let mut current = String::new();
    for line in script.lines() {
        let line = strip_comment(line);
        let (part, continued) = match line.trim_end().strip_suffix('\\') {
            Some(p) => (p, true),
            None => (line, false),
        };
        current.push(' ');
        current.push_str(part);
        if !continued {
            let command = current.split_whitespace().collect::<Vec<_>>().join(" ");
            if !command.is_empty() {
                out.push(command);
            }
            current.clear();
        }
    }
    out
}

/// `line` without a shell comment (a `#` at its start or after a blank, outside quotes).
fn strip_comment(line: &str) -> &str {
    let (mut single, mut double) = (false, false);
    let mut previous = ' ';
    for (i, c) in line.char_indices() {
        match c {
            '\'' if !double => single = !single,
            '"' if !single => double = !double,
            '#' if !single && !double && previous.is_whitespace() => return &line[..i],
            _ => {}
        }
        previous = c;
    }
    line
}

/// What is wrong with `how` for `block` that can be seen without running anything.
pub fn static_problems(root: &Path, block: &Block, how: &How) -> Vec<String> {
    let mut problems = Vec::new();
    match how {
        How::Doctest if !doctest_page(root, &block.page) => {
            problems.push(format!(
                "a doctest on a page src/lib.rs does not include (include_str!(\"../{}\"))",
                block.page
            ));
        }
        How::Ci => {
            let script = std::fs::read_to_string(root.join(".ci/run")).unwrap_or_default();
            // .ci/run runs the block itself when it names its page and its info string
            // (as it extracts docs/python.md's `sh install` block).
            let extracted =
                script.contains(&block.page) && script.contains(&format!("\"{}\"", block.info));
            let ci = commands(&script);
            for c in commands(&block.text()) {
                if !ci.contains(&c) && !extracted {
                    problems.push(format!("`{c}` is not a command of .ci/run"));
                }
            }
        }
        How::Test { file, name } => {
            let page = Path::new(&block.page)
                .file_name()
                .map(|n| n.to_string_lossy().into_owned())
                .unwrap_or_default();
            match std::fs::read_to_string(root.join(file)) {
                Err(e) => problems.push(format!("{file}: {e}")),
                Ok(text) => {
                    let defines = [format!("def {name}("), format!("fn {name}(")]
                        .iter()
                        .any(|d| text.contains(d.as_str()));
                    if !defines {
                        problems.push(format!("{file} defines no test `{name}`"));
                    }
                    if !text.contains(&page) {
                        problems.push(format!("{file} does not read {page}"));
                    }
                }
            }
        }
        How::Transcript if !block.body.first().is_some_and(|l| l.starts_with("$ ")) => {
            problems.push("a transcript starts with a `$ command` line".into());
        }
        How::Run { .. } if !matches!(block.lang(), "sh" | "bash" | "shell" | "python") => {
            problems.push(format!("cannot run a `{}` block", block.lang()));
        }
        How::Drawing if !matches!(block.lang(), "text" | "") => {
            problems.push("a drawing is a `text` block".into());
        }
        _ => {}
    }
    problems
}

/// A block and how it is run, or what is wrong with its annotation.
pub type Classified = (Block, Result<How, String>);

/// Every block of every page, with how it is run (or the error in its annotation).
pub fn all(root: &Path) -> Result<Vec<Classified>, String> {
    let mut out = Vec::new();
    for page in pages(root)? {
        let text = std::fs::read_to_string(root.join(&page)).map_err(|e| format!("{page}: {e}"))?;
        for block in parse(&page, &text)? {
            let how = how(root, &block).and_then(|how| {
                let problems = static_problems(root, &block, &how);
                if problems.is_empty() {
                    Ok(how)
                } else {
                    Err(problems.join("; "))
                }
            });
            out.push((block, how));
        }
    }
    Ok(out)
}
