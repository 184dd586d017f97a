//! Label placement for the benchmark's figure: each point label goes where it covers
//! no marker and no other label; the legend goes to the emptiest corner.

use plotters::prelude::SeriesLabelPosition;
use plotters::style::text_anchor::{HPos, VPos};

/// Estimated width (px) of `s` in the figure font at plotters size `size`: about
/// 0.56 em per character (SVG text is laid out by the viewer, not here).
pub(super) fn text_width(s: &str, size: u32) -> i32 {
    (s.chars().count() as f64 * 0.56 * f64::from(size) / 1.24).round() as i32
}

/// Greedy placement of point labels: each label takes the first of a few positions
/// around its point that overlaps no marker and no label placed before it, so that
/// close points (two CPUs at similar counts) stay readable.
pub(super) struct Labels {
    area: [i32; 4],
    pub(super) taken: Vec<[i32; 4]>,
}

impl Labels {
    pub(super) fn new(area: [i32; 4]) -> Self {
        Self {
            area,
            taken: Vec::new(),
        }
    }

    /// A marker of half-size `r` at `at`.
    pub(super) fn mark(&mut self, at: (i32, i32), r: i32) {
        self.taken.push([at.0 - r, at.1 - r, at.0 + r, at.1 + r]);
    }

    fn free(&self, b: [i32; 4]) -> bool {
        let [x0, y0, x1, y1] = self.area;
        b[0] >= x0
            && b[2] <= x1
            && b[1] >= y0
            && b[3] <= y1
            && self
                .taken
                .iter()
                .all(|t| b[2] <= t[0] || t[2] <= b[0] || b[3] <= t[1] || t[3] <= b[1])
    }

    /// Where to draw `label` for the point at `at`: anchor and position.
    pub(super) fn place(
        &mut self,
        at: (i32, i32),
        label: &str,
        size: u32,
    ) -> (HPos, VPos, (i32, i32)) {
        let (w, h) = (
            text_width(label, size),
            (f64::from(size) / 1.24).round() as i32,
        );
        let (x, y) = at;
        let d = 10;
        let candidates = [
            (HPos::Left, VPos::Center, (x + d, y)),
            (HPos::Right, VPos::Center, (x - d, y)),
            (HPos::Center, VPos::Bottom, (x, y - d)),
            (HPos::Center, VPos::Top, (x, y + d)),
            (HPos::Left, VPos::Center, (x + d, y - h - 2)),
            (HPos::Left, VPos::Center, (x + d, y + h + 2)),
            (HPos::Right, VPos::Center, (x - d, y - h - 2)),
            (HPos::Right, VPos::Center, (x - d, y + h + 2)),
        ];
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
        let choice = candidates
            .iter()
            .copied()
            .find(|c| self.free(bbox(*c)))
            .unwrap_or(candidates[0]);
        self.taken.push(bbox(choice));
        choice
    }

    /// The corner of the plotting area whose `(w, h)` box covers the fewest markers
    /// and labels (upper right first on ties).
    pub(super) fn emptiest_corner(&self, (w, h): (i32, i32)) -> SeriesLabelPosition {
        let [x0, y0, x1, y1] = self.area;
        let corners = [
            (SeriesLabelPosition::UpperRight, [x1 - w, y0, x1, y0 + h]),
            (SeriesLabelPosition::UpperLeft, [x0, y0, x0 + w, y0 + h]),
            (SeriesLabelPosition::LowerRight, [x1 - w, y1 - h, x1, y1]),
            (SeriesLabelPosition::LowerLeft, [x0, y1 - h, x0 + w, y1]),
        ];
        let hits = |b: &[i32; 4]| {
            self.taken
                .iter()
                .filter(|t| !(b[2] <= t[0] || t[2] <= b[0] || b[3] <= t[1] || t[3] <= b[1]))
                .count()
        };
        corners
            .into_iter()
            .min_by_key(|(_, b)| hits(b))
            .map_or(SeriesLabelPosition::UpperRight, |(p, _)| p)
    }
}
