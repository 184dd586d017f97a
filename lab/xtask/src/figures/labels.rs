//! Label placement for the benchmark's figures: each point label goes where it covers
//! no marker and no other label. The boxes of the labels placed are kept, so that a
//! test can check that none overlap.

use plotters::style::text_anchor::{HPos, VPos};

/// Estimated width (px) of `s` in the figure font at plotters size `size`: about
/// 0.56 em per character (SVG text is laid out by the viewer, not here), plus one
/// pixel either side.
pub(super) fn text_width(s: &str, size: u32) -> i32 {
    (s.chars().count() as f64 * 0.56 * f64::from(size) / 1.24).round() as i32 + 2
}

/// Height (px) of a line of text at plotters size `size`.
pub(super) fn text_height(size: u32) -> i32 {
    (f64::from(size) / 1.24).round() as i32
}

/// Whether two boxes `[x0, y0, x1, y1]` overlap (touching edges do not).
pub(super) fn overlap(a: &[i32; 4], b: &[i32; 4]) -> bool {
    !(a[2] <= b[0] || b[2] <= a[0] || a[3] <= b[1] || b[3] <= a[1])
}

/// Greedy placement of point labels: each label takes the first of the positions
/// around its point (right, left, above, below and the diagonals, near first, then
/// farther out) that stays in the plotting area and overlaps no marker, no label
/// placed before it and, where one such is left, no line.
pub(super) struct Labels {
    area: [i32; 4],
    /// Markers and labels: what a new label must not cover.
    pub(super) taken: Vec<[i32; 4]>,
    /// Lines: what a new label should not cover, if it can help it.
    pub(super) lines: Vec<[i32; 4]>,
    /// The boxes of the labels placed, in order.
    pub(super) placed: Vec<[i32; 4]>,
    /// Labels that found no free position (drawn at the first one regardless): a
    /// figure's tests require none.
    pub(super) crowded: Vec<String>,
}

impl Labels {
    pub(super) fn new(area: [i32; 4]) -> Self {
        Self {
            area,
            taken: Vec::new(),
            lines: Vec::new(),
            placed: Vec::new(),
            crowded: Vec::new(),
        }
    }

    /// A marker of half-size `r` at `at`.
    pub(super) fn mark(&mut self, at: (i32, i32), r: i32) {
        self.taken.push([at.0 - r, at.1 - r, at.0 + r, at.1 + r]);
    }

    /// A line from `a` to `b` (horizontal or vertical), `w` px wide.
    pub(super) fn line(&mut self, a: (i32, i32), b: (i32, i32), w: i32) {
        self.lines.push([
            a.0.min(b.0) - w,
            a.1.min(b.1) - w,
            a.0.max(b.0) + w,
            a.1.max(b.1) + w,
        ]);
    }

    /// Inside the area, on no marker or label, and (`strict`) on no line.
    fn free(&self, b: [i32; 4], strict: bool) -> bool {
        let [x0, y0, x1, y1] = self.area;
        b[0] >= x0
            && b[2] <= x1
            && b[1] >= y0
            && b[3] <= y1
            && self.taken.iter().all(|t| !overlap(t, &b))
            && (!strict || self.lines.iter().all(|t| !overlap(t, &b)))
    }

    /// Where to draw `label` for the point at `at`: anchor and position.
    pub(super) fn place(
        &mut self,
        at: (i32, i32),
        label: &str,
        size: u32,
    ) -> (HPos, VPos, (i32, i32)) {
        let (w, h) = (text_width(label, size), text_height(size));
        let (x, y) = at;
        let mut candidates = Vec::new();
        for d in [10, 18, 30, 46] {
            let s = h / 2 + d / 2; // vertical offset of the diagonals
            candidates.extend([
                (HPos::Left, VPos::Center, (x + d, y)),
                (HPos::Right, VPos::Center, (x - d, y)),
                (HPos::Center, VPos::Bottom, (x, y - d)),
                (HPos::Center, VPos::Top, (x, y + d)),
                (HPos::Left, VPos::Center, (x + d, y - s)),
                (HPos::Left, VPos::Center, (x + d, y + s)),
                (HPos::Right, VPos::Center, (x - d, y - s)),
                (HPos::Right, VPos::Center, (x - d, y + s)),
            ]);
        }
        let bbox = |(hp, vp, (px, py)): (HPos, VPos, (i32, i32))| {
            let x0 = match hp {
                HPos::Left => px,
                HPos::Center => px - w / 2,
                HPos::Right => px - w,
            };
            let y0 = match vp {
                VPos::Top => py,
                VPos::Center => py - h / 2,
                VPos::Bottom => py - h,
            };
            [x0, y0, x0 + w, y0 + h]
        };
        let choice = match candidates
            .iter()
            .copied()
            .find(|c| self.free(bbox(*c), true))
            .or_else(|| {
                candidates
                    .iter()
                    .copied()
                    .find(|c| self.free(bbox(*c), false))
            }) {
            Some(c) => c,
            None => {
                self.crowded.push(label.to_string());
                candidates[0]
            }
        };
        self.taken.push(bbox(choice));
        self.placed.push(bbox(choice));
        choice
    }
}

/// What a figure's labels came to: every label box placed, and those that found no
/// free place. Tests hold both to "none overlap" and "none crowded".
#[derive(Debug, Default)]
pub struct LabelReport {
    pub boxes: Vec<[i32; 4]>,
    pub crowded: Vec<String>,
}

impl LabelReport {
    pub(super) fn add(&mut self, labels: Labels) {
        self.boxes.extend(labels.placed);
        self.crowded.extend(labels.crowded);
    }

    /// Pairs of label boxes that overlap.
    pub fn overlaps(&self) -> Vec<([i32; 4], [i32; 4])> {
        let mut out = Vec::new();
        for (i, a) in self.boxes.iter().enumerate() {
            for b in &self.boxes[i + 1..] {
                if overlap(a, b) {
                    out.push((*a, *b));
                }
            }
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn labels_avoid_markers_and_each_other() {
        let mut labels = Labels::new([0, 0, 400, 300]);
        let points = [(100, 100), (104, 104), (108, 100), (100, 108)];
        for p in points {
            labels.mark(p, 6);
        }
        for (i, p) in points.iter().enumerate() {
            labels.place(*p, &format!("label number {i}"), 17);
        }
        let mut report = LabelReport::default();
        report.add(labels);
        assert!(report.crowded.is_empty(), "{:?}", report.crowded);
        assert!(report.overlaps().is_empty());
        assert_eq!(report.boxes.len(), 4);
    }

    #[test]
    fn a_label_with_no_room_is_reported() {
        let mut labels = Labels::new([0, 0, 40, 20]);
        labels.place((20, 10), "far too long a label", 17);
        assert_eq!(labels.crowded, ["far too long a label"]);
    }
}
