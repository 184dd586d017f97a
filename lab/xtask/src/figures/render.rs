//! `cargo xtask figures --renderers`: every SVG the repository draws renders the same in
//! Chromium, librsvg (`rsvg-convert`) and ImageMagick (`convert`): each committed SVG
//! under docs/ and the monitor example's two figures, rasterised by the three at the
//! SVG's own size, compared pair by pair.
//!
//! The comparison: both images averaged over 8x8-pixel blocks; a block differs when
//! one of its mean channels differs by more than [`BLOCK_TOLERANCE`] of full scale; a
//! pair fails when more than [`MAX_DIFFERING`] of its blocks differ. Fonts rasterise
//! differently in each (hinting, weight), which moves a block's mean by less than that;
//! a black fill, a missing or misplaced label, a line closed back to its start do not
//! (measured on docs/'s six figures: before `misalign_cli::svg::portable`, Chromium
//! and librsvg differed in 0.6-1.1 % of their blocks (each its own sans-serif font)
//! and ImageMagick from both in 6-33 %; after it, in at most 0.03 %). The PNGs stay
//! under `target/figures-render/` to be looked at.

use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};

/// A block differs when a mean channel moves by more than this (of 1).
pub const BLOCK_TOLERANCE: f64 = 0.2;
/// A pair fails when more than this fraction of its blocks differ.
pub const MAX_DIFFERING: f64 = 1e-3;
const BLOCK: usize = 8;

/// The three renderers, as [`render`] runs them.
const RENDERERS: [&str; 3] = ["chromium", "rsvg", "imagemagick"];

fn run(cmd: &mut Command) -> Result<Vec<u8>, String> {
    let out = cmd
        .stdin(Stdio::null())
        .output()
        .map_err(|e| format!("cannot run {:?}: {e}", cmd.get_program()))?;
    if out.status.success() {
        Ok(out.stdout)
    } else {
        Err(format!(
            "{:?} failed: {}",
            cmd.get_program(),
            String::from_utf8_lossy(&out.stderr)
        ))
    }
}

/// The `width` and `height` of the `<svg>` element, px.
fn size(svg: &str) -> Result<(u32, u32), String> {
    let tag = &svg[svg.find("<svg").ok_or("no <svg> element")?..];
    let tag = &tag[..tag.find('>').ok_or("an unclosed <svg> element")?];
    let attr = |name: &str| -> Result<u32, String> {
        let at = tag
            .find(&format!(" {name}=\""))
            .ok_or_else(|| format!("<svg> without {name}"))?;
        let rest = &tag[at + name.len() + 3..];
        rest[..rest.find('"').unwrap_or(0)]
            .parse()
            .map_err(|_| format!("<svg> {name} is not a whole number of px"))
    };
    Ok((attr("width")?, attr("height")?))
}

/// Rasterises `svg` with `renderer` into `png`.
fn render(
    renderer: &str,
    svg: &Path,
    png: &Path,
    (w, h): (u32, u32),
    scratch: &Path,
) -> Result<(), String> {
    match renderer {
        "chromium" => {
            let profile = scratch.join("chromium-profile");
            let _ = std::fs::remove_dir_all(&profile);
            let url = format!("file://{}", svg.display());
            run(Command::new("chromium").args([
                "--headless",
                "--no-sandbox",
                "--disable-gpu",
                "--disable-quic",
                "--no-first-run",
                "--disable-background-networking",
                "--disable-component-update",
                "--disable-sync",
                "--hide-scrollbars",
                "--force-device-scale-factor=1",
                &format!("--user-data-dir={}", profile.display()),
                &format!("--window-size={w},{h}"),
                &format!("--screenshot={}", png.display()),
                &url,
            ]))?;
        }
        "rsvg" => {
            run(Command::new("rsvg-convert")
                .args([
                    "-w",
                    &w.to_string(),
                    "-h",
                    &h.to_string(),
                    "-b",
                    "white",
                    "-o",
                ])
                .arg(png)
                .arg(svg))?;
        }
        _ => {
            run(Command::new("convert")
                .args(["-background", "white", "-flatten"])
                .arg(svg)
                .arg(png))?;
        }
    }
    Ok(())
}

/// The RGB bytes of `png` over white, with its size (decoded by ImageMagick).
fn pixels(png: &Path) -> Result<((usize, usize), Vec<u8>), String> {
    let dims = run(Command::new("identify").args(["-format", "%w %h"]).arg(png))?;
    let dims = String::from_utf8_lossy(&dims);
    let mut it = dims.split_whitespace().map(str::parse::<usize>);
    let (Some(Ok(w)), Some(Ok(h))) = (it.next(), it.next()) else {
        return Err(format!("{}: no size", png.display()));
    };
    let rgb = run(Command::new("convert").arg(png).args([
        "-background",
        "white",
        "-alpha",
        "remove",
        "-alpha",
        "off",
        "-depth",
        "8",
        "rgb:-",
    ]))?;
    if rgb.len() != w * h * 3 {
        return Err(format!(
            "{}: {} bytes for {w}x{h}",
            png.display(),
            rgb.len()
        ));
    }
    Ok(((w, h), rgb))
}

/// The fraction of 8x8 blocks whose mean colour differs by more than
/// [`BLOCK_TOLERANCE`] in a channel.
pub fn differing_blocks((w, h): (usize, usize), a: &[u8], b: &[u8]) -> f64 {
    let (bw, bh) = (w / BLOCK, h / BLOCK);
    let mut differing = 0usize;
    for by in 0..bh {
        for bx in 0..bw {
            let mut sum = [0i64; 3];
            for y in by * BLOCK..(by + 1) * BLOCK {
                for x in bx * BLOCK..(bx + 1) * BLOCK {
                    let i = (y * w + x) * 3;
                    for c in 0..3 {
                        sum[c] += i64::from(a[i + c]) - i64::from(b[i + c]);
                    }
                }
            }
            let n = (BLOCK * BLOCK * 255) as f64;
            if sum.iter().any(|s| (*s as f64 / n).abs() > BLOCK_TOLERANCE) {
                differing += 1;
            }
        }
    }
    differing as f64 / (bw * bh).max(1) as f64
}

/// The SVGs to render: docs/*.svg and the monitor example's figures, drawn into
/// `scratch` from the built-in scenario.
fn svgs(root: &Path, scratch: &Path) -> Result<Vec<PathBuf>, String> {
    let mut out: Vec<PathBuf> = std::fs::read_dir(root.join("docs"))
        .map_err(|e| format!("docs: {e}"))?
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|e| e == "svg"))
        .collect();
    out.sort();
    let plot = scratch.join("monitor.svg");
    let args: Vec<String> = [
        "--plot".to_string(),
        plot.display().to_string(),
        "--thresholds".to_string(),
        scratch.join("thresholds.csv").display().to_string(),
    ]
    .into();
    let (mut stdout, mut stderr) = (Vec::new(), Vec::new());
    if misalign_cli::monitor::run(&args, &mut stdout, &mut stderr, false) != 0 {
        return Err(format!(
            "the monitor example: {}",
            String::from_utf8_lossy(&stderr)
        ));
    }
    out.push(plot);
    out.push(scratch.join("monitor-thresholds.svg"));
    Ok(out)
}

/// `cargo xtask figures --renderers`.
pub fn check(root: &Path) -> Result<bool, String> {
    let root = &root
        .canonicalize()
        .map_err(|e| format!("{}: {e}", root.display()))?;
    let scratch = root.join("target/figures-render");
    let _ = std::fs::remove_dir_all(&scratch);
    std::fs::create_dir_all(&scratch).map_err(|e| format!("{}: {e}", scratch.display()))?;
    let mut ok = true;
    for svg in svgs(root, &scratch)? {
        let name = svg
            .file_stem()
            .unwrap_or_default()
            .to_string_lossy()
            .into_owned();
        let text = std::fs::read_to_string(&svg).map_err(|e| format!("{}: {e}", svg.display()))?;
        let dims = size(&text).map_err(|e| format!("{}: {e}", svg.display()))?;
        let mut images = Vec::new();
        for renderer in RENDERERS {
            let png = scratch.join(format!("{name}-{renderer}.png"));
            render(renderer, &svg, &png, dims, &scratch)
                .map_err(|e| format!("{name}: {renderer}: {e}"))?;
            let (got, rgb) = pixels(&png)?;
            if got != (dims.0 as usize, dims.1 as usize) {
                println!(
                    "{name}: {renderer} drew {}x{} px, not {}x{}",
                    got.0, got.1, dims.0, dims.1
                );
                ok = false;
                continue;
            }
            images.push((renderer, rgb));
        }
        for i in 0..images.len() {
            for j in i + 1..images.len() {
                let (a, b) = (&images[i], &images[j]);
                let f = differing_blocks((dims.0 as usize, dims.1 as usize), &a.1, &b.1);
                let pass = f <= MAX_DIFFERING;
                ok &= pass;
                println!(
                    "{} {name}: {} and {} differ in {:.3} % of 8x8 blocks (at most {:.1} %)",
                    if pass { "ok    " } else { "FAILED" },
                    a.0,
                    b.0,
                    f * 100.0,
                    MAX_DIFFERING * 100.0
                );
            }
        }
    }
    println!("renderings in {}", scratch.display());
    Ok(ok)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn blocks_differ_by_their_mean() {
        let (w, h) = (16, 8);
        let white = vec![255u8; w * h * 3];
        // One black pixel in a block moves its mean by 1/64: not a difference.
        let mut dot = white.clone();
        dot[..3].fill(0);
        assert_eq!(differing_blocks((w, h), &white, &dot), 0.0);
        // A black block is.
        let mut block = white.clone();
        for y in 0..8 {
            block[y * w * 3..(y * w + 8) * 3].fill(0);
        }
        assert_eq!(differing_blocks((w, h), &white, &block), 0.5);
        assert_eq!(
            size(r#"<svg width="800" height="600" viewBox="0 0 800 600">"#),
            Ok((800, 600))
        );
    }
}
