//! SVG that renders the same in a browser (Chromium), librsvg and ImageMagick's own
//! renderer: plotters' output rewritten where ImageMagick reads it otherwise.
//!
//! ImageMagick (6.9, its internal MSVG renderer) ignores every `opacity`,
//! `fill-opacity` and `stroke-opacity`; fills a `fill="none"` shape black when an
//! `opacity` attribute follows; strokes a shape without a `stroke` attribute, and its
//! text, in black; draws spikes at sharp mitred joins of a polyline; places `dy` by its
//! own measure; rotates text the other way; and reads no font list. So [`portable`]
//! blends every opacity into an opaque colour over the white background, says
//! `stroke="none"` where no stroke is meant, joins polylines round, moves `dy` into `y`,
//! names one font, and refuses rotated text (draw axis titles horizontally).

/// The font every renderer here has (a generic family is resolved differently by
/// each: Chromium takes Liberation Sans, librsvg and ImageMagick DejaVu Sans).
pub const FONT: &str = "DejaVu Sans";

/// An `ex` of the font, in `em` (DejaVu Sans' x-height).
const EX_PER_EM: f64 = 0.55;

/// `#RRGGBB` at `alpha` over white, as an opaque `#RRGGBB`.
fn over_white(colour: &str, alpha: f64) -> Option<String> {
    let hex = colour.strip_prefix('#').filter(|h| h.len() == 6)?;
    let channel = |i: usize| u8::from_str_radix(&hex[i..i + 2], 16).ok();
    let blend = |c: u8| (255.0 - alpha * (255.0 - f64::from(c))).round() as u8;
    let (r, g, b) = (channel(0)?, channel(2)?, channel(4)?);
    Some(format!("#{:02X}{:02X}{:02X}", blend(r), blend(g), blend(b)))
}

/// One start tag: its name, its attributes in order, whether it closes itself.
struct Tag {
    name: String,
    attrs: Vec<(String, String)>,
    empty: bool,
}

impl Tag {
    fn parse(inner: &str) -> Result<Tag, String> {
        let empty = inner.ends_with('/');
        let inner = inner.trim_end_matches('/');
        let (name, mut rest) = inner.split_once(char::is_whitespace).unwrap_or((inner, ""));
        let mut attrs = Vec::new();
        loop {
            rest = rest.trim_start();
            if rest.is_empty() {
                break;
            }
            let (key, after) = rest
                .split_once("=\"")
                .ok_or_else(|| format!("<{name}>: cannot read `{rest}`"))?;
            let (value, after) = after
                .split_once('"')
                .ok_or_else(|| format!("<{name}>: unterminated attribute {key}"))?;
            attrs.push((key.trim().to_string(), value.to_string()));
            rest = after;
        }
        Ok(Tag {
            name: name.to_string(),
            attrs,
            empty,
        })
    }

    fn get(&self, key: &str) -> Option<&str> {
        self.attrs
            .iter()
            .find(|(k, _)| k == key)
            .map(|(_, v)| v.as_str())
    }

    fn set(&mut self, key: &str, value: String) {
        match self.attrs.iter_mut().find(|(k, _)| k == key) {
            Some(a) => a.1 = value,
            None => self.attrs.push((key.to_string(), value)),
        }
    }

    fn remove(&mut self, key: &str) -> Option<String> {
        let i = self.attrs.iter().position(|(k, _)| k == key)?;
        Some(self.attrs.remove(i).1)
    }

    fn write(&self) -> String {
        let mut s = format!("<{}", self.name);
        for (k, v) in &self.attrs {
            s.push_str(&format!(" {k}=\"{v}\""));
        }
        s.push_str(if self.empty { "/>" } else { ">" });
        s
    }

    /// Blends the opacities into the colours (over white) and removes them.
    fn opaque(&mut self) -> Result<(), String> {
        let name = self.name.clone();
        let number = |v: String| {
            v.parse::<f64>()
                .map_err(|_| format!("<{name}>: opacity `{v}`"))
        };
        let all = self
            .remove("opacity")
            .map(number)
            .transpose()?
            .unwrap_or(1.0);
        for (paint, own) in [("fill", "fill-opacity"), ("stroke", "stroke-opacity")] {
            let alpha = all * self.remove(own).map(number).transpose()?.unwrap_or(1.0);
            if let Some(colour) = self.get(paint).map(str::to_string)
                && alpha < 1.0
                && colour != "none"
            {
                let blended = over_white(&colour, alpha)
                    .ok_or_else(|| format!("<{}>: {paint} `{colour}` with opacity", self.name))?;
                self.set(paint, blended);
            }
        }
        Ok(())
    }

    /// Moves `dy` (em, ex or px) into `y`, names the font, and refuses rotated text.
    fn text(&mut self) -> Result<(), String> {
        if self.get("transform").is_some_and(|t| t.contains("rotate")) {
            return Err(
                "rotated text is drawn the other way round by ImageMagick: set the axis title \
                 horizontally"
                    .into(),
            );
        }
        let size: f64 = self
            .get("font-size")
            .and_then(|s| s.parse().ok())
            .ok_or("<text> without a font-size")?;
        if let Some(dy) = self.remove("dy") {
            let px = if let Some(v) = dy.strip_suffix("em") {
                v.parse::<f64>().map(|v| v * size)
            } else if let Some(v) = dy.strip_suffix("ex") {
                v.parse::<f64>().map(|v| v * size * EX_PER_EM)
            } else {
                dy.trim_end_matches("px").parse::<f64>()
            }
            .map_err(|_| format!("<text> dy `{dy}`"))?;
            let y: f64 = self
                .get("y")
                .and_then(|s| s.parse().ok())
                .ok_or("<text> with dy and without y")?;
            self.set("y", format!("{}", ((y + px) * 10.0).round() / 10.0));
        }
        self.set("font-family", FONT.to_string());
        if self.get("stroke").is_none() {
            self.set("stroke", "none".into());
        }
        Ok(())
    }
}

/// `svg` (plotters' output) rewritten to render the same in Chromium, librsvg and
/// ImageMagick; an error names what cannot be (rotated text).
pub fn portable(svg: &str) -> Result<String, String> {
    let mut out = String::with_capacity(svg.len());
    let mut rest = svg;
    while let Some(open) = rest.find('<') {
        out.push_str(&rest[..open]);
        let close = rest[open..].find('>').ok_or("a tag is never closed")? + open;
        let inner = &rest[open + 1..close];
        rest = &rest[close + 1..];
        if inner.starts_with(['/', '?', '!']) {
            out.push_str(&format!("<{inner}>"));
            continue;
        }
        let mut tag = Tag::parse(inner)?;
        tag.opaque()?;
        // What a renderer would otherwise choose on its own: the joins of a line, the
        // stroke of a filled shape.
        let default = match tag.name.as_str() {
            "text" => {
                tag.text()?;
                None
            }
            "polyline" | "path" => Some(("stroke-linejoin", "round")),
            "polygon" | "rect" | "circle" | "ellipse" => Some(("stroke", "none")),
            _ => None,
        };
        if let Some((key, value)) = default
            && tag.get(key).is_none()
        {
            tag.set(key, value.into());
        }
        out.push_str(&tag.write());
    }
    out.push_str(rest);
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn opacity_becomes_an_opaque_colour() {
        let svg = r##"<svg><polyline fill="none" opacity="1" stroke="#000000" points="1,2 3,4 "/><line opacity="0.2" stroke="#000000" x1="0"/><rect fill="#0072B2" fill-opacity="0.5"/></svg>"##;
        assert_eq!(
            portable(svg).unwrap(),
            r##"<svg><polyline fill="none" stroke="#000000" points="1,2 3,4 " stroke-linejoin="round"/><line stroke="#CCCCCC" x1="0"/><rect fill="#80B9D9" stroke="none"/></svg>"##
        );
    }

    #[test]
    fn text_is_placed_by_y_in_one_font() {
        let svg = r##"<text x="8" y="98" dy="0.5em" font-family="sans-serif" font-size="10" fill="#000000">t &lt; 1</text>"##;
        assert_eq!(
            portable(svg).unwrap(),
            r##"<text x="8" y="103" font-family="DejaVu Sans" font-size="10" fill="#000000" stroke="none">t &lt; 1</text>"##
        );
        let rotated =
            r#"<text x="8" y="98" font-size="10" transform="rotate(270, 8, 98)">F</text>"#;
        assert!(portable(rotated).is_err());
    }
}
