//! A JSON object written field by field, for the page's summaries (numbers as Rust
//! prints them, NaN and infinities as null).

/// An object being written.
pub struct Object(String);

impl Object {
    pub fn new() -> Self {
        Object(String::from("{"))
    }

    fn key(&mut self, key: &str) {
        if self.0.len() > 1 {
            self.0.push(',');
        }
        self.0.push_str(&quoted(key));
        self.0.push(':');
    }

    /// `"key": number` (null when not finite).
    pub fn num(&mut self, key: &str, x: f64) {
        self.key(key);
        if x.is_finite() {
            self.0.push_str(&x.to_string());
        } else {
            self.0.push_str("null");
        }
    }

    /// `"key": number` or null.
    pub fn opt(&mut self, key: &str, x: Option<f64>) {
        self.num(key, x.unwrap_or(f64::NAN));
    }

    /// `"key": "text"`.
    pub fn str(&mut self, key: &str, text: &str) {
        self.key(key);
        self.0.push_str(&quoted(text));
    }

    /// `"key": ` and JSON written already.
    pub fn raw(&mut self, key: &str, json: &str) {
        self.key(key);
        self.0.push_str(json);
    }

    /// The object's text.
    pub fn end(mut self) -> String {
        self.0.push('}');
        self.0
    }
}

/// `text` as a JSON string.
fn quoted(text: &str) -> String {
    let mut out = String::from("\"");
    for c in text.chars() {
        match c {
            '"' => out.push_str("\\\""),
            '\\' => out.push_str("\\\\"),
            c if (c as u32) < 0x20 => out.push_str(&format!("\\u{:04x}", c as u32)),
            c => out.push(c),
        }
    }
    out.push('"');
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fields_are_valid_json() {
        let mut o = Object::new();
        o.num("a", 1.5);
        o.opt("b", None);
        o.str("c", "row 3: \"x\"\u{1}\\");
        o.raw("d", "[1,2]");
        assert_eq!(
            o.end(),
            r#"{"a":1.5,"b":null,"c":"row 3: \"x\"\u0001\\","d":[1,2]}"#
        );
    }
}
