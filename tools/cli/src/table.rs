//! The rules both host tools read their CSV files by (the estimator's input, the
//! monitor example's scene and trace): the header is the first record; each column a
//! tool reads appears once (a repeated one is an error naming it); a file whose
//! header only splits on `;` is read as `;`-separated, and the tool says so on stderr
//! ([`SEMICOLON_NOTE`]); a number is UTF-8, a decimal f64 and inside f64's range, and
//! its error names the column ([`number`]).

/// What a tool says on stderr when it reads a `;`-separated file.
pub const SEMICOLON_NOTE: &str =
    "the input is ';'-separated; reading it so (numbers need a decimal point)";

/// A number from one field of column `name`: UTF-8, a decimal f64, and inside f64's
/// range (1e400 is refused, not read as infinity; 1e-400 is refused, not read as 0).
pub fn number(name: &str, field: &[u8]) -> Result<f64, String> {
    let text = std::str::from_utf8(field)
        .map_err(|_| format!("{name}: not UTF-8"))?
        .trim();
    let x: f64 = text
        .parse()
        .map_err(|_| format!("{name}: not a number: {text:?}"))?;
    // Asked only of an infinity or a zero: the common number costs no more.
    let mantissa = || text.split(['e', 'E']).next().unwrap_or("");
    // An infinity written as one (`inf`, `-Infinity`) is a number; one from overflow
    // is not.
    let literal_inf = || mantissa().to_ascii_lowercase().contains("inf");
    if x.is_infinite() && !literal_inf() {
        return Err(format!(
            "{name} = {text} is outside the range of f64 numbers (|x| <= 1.8e308)"
        ));
    }
    if x == 0.0 && mantissa().bytes().any(|b| (b'1'..=b'9').contains(&b)) {
        return Err(format!(
            "{name} = {text} is below the smallest f64 number (4.9e-324)"
        ));
    }
    Ok(x)
}

/// What is wrong with a row's bytes, if anything, before its numbers are read.
pub fn bad_record(record: &csv::ByteRecord, fields: usize) -> Option<String> {
    if record.len() != fields {
        return Some(format!(
            "row has {} fields, the header {fields}",
            record.len()
        ));
    }
    for (k, field) in record.iter().enumerate() {
        if field.contains(&0) {
            return Some(format!("field {} holds a NUL byte", k + 1));
        }
        if std::str::from_utf8(field).is_err() {
            return Some(format!("field {} is not UTF-8", k + 1));
        }
    }
    None
}

/// Whether a field is empty (or only blanks): an optional cell left unset.
pub fn is_blank(field: &[u8]) -> bool {
    field.iter().all(u8::is_ascii_whitespace)
}

/// Where column `name` is in `header` (names compared after trimming blanks): `None`
/// when absent, `Err` naming it when it appears more than once.
pub fn find_column<'a>(
    header: impl IntoIterator<Item = &'a [u8]>,
    name: &str,
) -> Result<Option<usize>, String> {
    let at: Vec<usize> = header
        .into_iter()
        .enumerate()
        .filter(|(_, h)| h.trim_ascii() == name.as_bytes())
        .map(|(i, _)| i)
        .collect();
    match at.as_slice() {
        [] => Ok(None),
        [i] => Ok(Some(*i)),
        _ => Err(format!(
            "column {name} appears {} times in the header (columns {}); keep one",
            at.len(),
            at.iter()
                .map(|i| (i + 1).to_string())
                .collect::<Vec<_>>()
                .join(", ")
        )),
    }
}

/// Where the columns `needed` (all of them, else an error listing them) and `optional`
/// are in `header`.
pub fn find_columns<'a>(
    header: impl IntoIterator<Item = &'a [u8]> + Clone,
    needed: &[&str],
    optional: &[&str],
) -> Result<(Vec<usize>, Vec<Option<usize>>), String> {
    let mut at = Vec::with_capacity(needed.len());
    for name in needed {
        at.push(
            find_column(header.clone(), name)?
                .ok_or_else(|| format!("input lacks column {name} (needs {})", needed.join(",")))?,
        );
    }
    let maybe = optional
        .iter()
        .map(|name| find_column(header.clone(), name))
        .collect::<Result<_, _>>()?;
    Ok((at, maybe))
}

/// The header record of `first` (the file's first line or all of it) split on
/// `delimiter`, its names trimmed.
fn header_with(delimiter: u8, first: &[u8]) -> Option<csv::ByteRecord> {
    let mut reader = csv::ReaderBuilder::new()
        .delimiter(delimiter)
        .has_headers(true)
        .flexible(true)
        .trim(csv::Trim::All)
        .from_reader(first);
    reader
        .byte_headers()
        .ok()
        .filter(|h| !h.iter().all(<[u8]>::is_empty))
        .cloned()
}

/// The header of a file whose first record is in `first`, and its delimiter: `,`, or
/// `;` when the header is one `,`-field holding a `;` and only `;` gives the columns
/// `needed` (a tool then prints [`SEMICOLON_NOTE`]). `Err` when there is no header.
pub fn header(first: &[u8], needed: &[&str]) -> Result<(u8, csv::ByteRecord), String> {
    let no_header = || format!("input has no header (needs {})", needed.join(","));
    let comma = header_with(b',', first).ok_or_else(no_header)?;
    let has = |h: &csv::ByteRecord| find_columns(h, needed, &[]).is_ok();
    if !has(&comma)
        && comma.len() == 1
        && comma[0].contains(&b';')
        && let Some(semi) = header_with(b';', first).filter(has)
    {
        return Ok((b';', semi));
    }
    Ok((b',', comma))
}

/// A reader of one line's fields by the CSV rules (quotes, `""` inside them), with
/// buffers reused from line to line: a trace's rows are read line by line, so that a
/// bad line (an unterminated quote, say) spoils that row only.
#[derive(Debug)]
pub struct LineSplitter {
    core: csv_core::Reader,
    out: Vec<u8>,
    ends: Vec<usize>,
    fields: usize,
}

impl LineSplitter {
    /// A splitter of `delimiter`-separated lines.
    pub fn new(delimiter: u8) -> Self {
        LineSplitter {
            core: csv_core::ReaderBuilder::new().delimiter(delimiter).build(),
            out: vec![0; 256],
            ends: vec![0; 16],
            fields: 0,
        }
    }

    /// Splits `line` (without its line end); then [`field`](Self::field) reads its
    /// fields. `Err` for an unterminated quote.
    pub fn split(&mut self, line: &[u8]) -> Result<(), String> {
        if line.iter().filter(|&&b| b == b'"').count() % 2 == 1 {
            self.fields = 0;
            return Err("unterminated quote".into());
        }
        self.core.reset();
        let (mut input, mut o, mut e) = (line, 0, 0);
        loop {
            let (result, nin, nout, nend) =
                self.core
                    .read_record(input, &mut self.out[o..], &mut self.ends[e..]);
            (input, o, e) = (&input[nin..], o + nout, e + nend);
            match result {
                csv_core::ReadRecordResult::OutputFull => self.out.resize(2 * self.out.len(), 0),
                csv_core::ReadRecordResult::OutputEndsFull => {
                    self.ends.resize(2 * self.ends.len(), 0);
                }
                // The line is all read: the empty input that follows is its end.
                csv_core::ReadRecordResult::InputEmpty => {}
                csv_core::ReadRecordResult::Record | csv_core::ReadRecordResult::End => break,
            }
        }
        self.fields = e;
        Ok(())
    }

    /// How many fields the last line split into.
    pub fn len(&self) -> usize {
        self.fields
    }

    /// Whether the last line had no field.
    pub fn is_empty(&self) -> bool {
        self.fields == 0
    }

    /// Field `i` of the last line (empty when there is none).
    pub fn field(&self, i: usize) -> &[u8] {
        if i >= self.fields {
            return b"";
        }
        let start = if i == 0 { 0 } else { self.ends[i - 1] };
        &self.out[start..self.ends[i]]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_repeated_column_is_named() {
        let h = csv::ByteRecord::from(vec!["t", "phi", " phi"]);
        let e = find_columns(&h, &["t", "phi"], &[]).unwrap_err();
        assert!(e.contains("column phi appears 2 times"), "{e}");
        let e = find_columns(&h, &["t"], &["phi"]).unwrap_err();
        assert!(e.contains("column phi appears 2 times"), "{e}");
        assert_eq!(find_column(&h, "t"), Ok(Some(0)));
    }

    #[test]
    fn a_semicolon_header_is_detected_only_when_it_gives_the_columns() {
        let (d, h) = header(b"t;P;phi\n", &["t", "P", "phi"]).unwrap();
        assert_eq!((d, h.len()), (b';', 3));
        let (d, h) = header(b"t,P,phi\n", &["t", "P", "phi"]).unwrap();
        assert_eq!((d, h.len()), (b',', 3));
        // Neither gives the columns: the ','-split header, whose lack is then reported.
        let (d, _) = header(b"a;b\n", &["t"]).unwrap();
        assert_eq!(d, b',');
        assert!(header(b"", &["t"]).is_err());
    }

    #[test]
    fn lines_split_by_the_csv_rules() {
        let mut s = LineSplitter::new(b',');
        s.split(br#"1,"2,5","a""b",,"#).unwrap();
        assert_eq!(s.len(), 5);
        assert_eq!(s.field(1), b"2,5");
        assert_eq!(s.field(2), b"a\"b");
        assert_eq!(
            (s.field(3), s.field(4), s.field(9)),
            (&b""[..], &b""[..], &b""[..])
        );
        let long = vec![b'9'; 1000];
        s.split(&long).unwrap();
        assert_eq!((s.len(), s.field(0).len()), (1, 1000));
        assert!(s.split(b"1,\"2").is_err());
        assert!(s.is_empty());
    }
}
