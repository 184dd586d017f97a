//! The images' log lines: `<marker> key=value key=value ...` as defmt-print prints
//! them (values without spaces; f32 in Rust's shortest round-trip form, so they read
//! back bit for bit). Every chore that reads an image's log reads it here.

use std::str::FromStr;

/// The `key=value` fields of one log line, from its marker on.
#[derive(Debug, Clone)]
pub struct Fields<'a>(Vec<(&'a str, &'a str)>);

impl<'a> Fields<'a> {
    /// The fields of `line` from `marker` on (`bench model=`, `event seq=`, ...);
    /// `None` if the line has no such marker.
    pub fn of(line: &'a str, marker: &str) -> Option<Self> {
        let rest = &line[line.find(marker)?..];
        Some(Fields(
            rest.split_whitespace()
                .filter_map(|kv| kv.split_once('='))
                .collect(),
        ))
    }

    /// The fields of the first line of `log` that holds `marker`.
    pub fn first(log: &'a str, marker: &str) -> Result<Self, String> {
        log.lines()
            .find_map(|l| Fields::of(l, marker))
            .ok_or_else(|| format!("no `{marker}` line in the log"))
    }

    /// Every line of `log` that holds `marker`, as fields.
    pub fn all(log: &'a str, marker: &'a str) -> impl Iterator<Item = Fields<'a>> + 'a {
        log.lines().filter_map(move |l| Fields::of(l, marker))
    }

    /// The value of `key`.
    pub fn get(&self, key: &str) -> Result<&'a str, String> {
        self.0
            .iter()
            .find(|(k, _)| *k == key)
            .map(|(_, v)| *v)
            .ok_or_else(|| format!("no `{key}=`"))
    }

    /// The value of `key`, parsed.
    pub fn num<T: FromStr>(&self, key: &str) -> Result<T, String> {
        let v = self.get(key)?;
        v.parse()
            .map_err(|_| format!("`{key}={v}` is not a number"))
    }

    /// An f32 value, exactly, as f64.
    pub fn f32(&self, key: &str) -> Result<f64, String> {
        self.num::<f32>(key).map(f64::from)
    }

    /// `None` or `Some(x)`, as defmt prints an `Option<f32>`.
    pub fn opt_f32(&self, key: &str) -> Result<Option<f64>, String> {
        match self.get(key)? {
            "None" => Ok(None),
            v => v
                .strip_prefix("Some(")
                .and_then(|v| v.strip_suffix(')'))
                .and_then(|v| v.parse::<f32>().ok())
                .map(|x| Some(f64::from(x)))
                .ok_or_else(|| format!("`{key}={v}` is neither None nor Some(number)")),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::Fields;

    #[test]
    fn fields_are_read_from_the_marker_on() {
        let line = "INFO bench model=f32 op=estimate n=256 mean=96 max=117";
        let f = Fields::of(line, "bench model=").unwrap();
        assert_eq!(f.get("model"), Ok("f32"));
        assert_eq!(f.num::<u64>("max"), Ok(117));
        assert!(f.num::<u64>("model").is_err());
        assert!(f.get("min").is_err());
        assert!(Fields::of("bench ticks_per_1000=1600", "bench model=").is_none());
        let e = Fields::of("event seq=3 ttc=Some(1.5) phi0=None s=0.1", "event seq=").unwrap();
        assert_eq!(e.opt_f32("ttc"), Ok(Some(1.5)));
        assert_eq!(e.opt_f32("phi0"), Ok(None));
        assert_eq!(e.f32("s"), Ok(f64::from(0.1f32)));
        let log = "a\nnode core=m0 stack_bytes=12\nnode core=m4 stack_bytes=9\n";
        assert_eq!(
            Fields::first(log, "node core=").unwrap().get("core"),
            Ok("m0")
        );
        assert_eq!(Fields::all(log, "node core=").count(), 2);
        assert!(Fields::first(log, "result model=").is_err());
    }
}
