//! Minimal SVG line plots (no dependencies): axes with round-number ticks (a linear or a log
//! y axis), one polyline per series with an optional shaded band, a legend. Opens in any
//! browser.

use std::fmt::Write;

/// One curve: a name for the legend, a CSS colour, a dash pattern (`""` for solid), x and y,
/// and optionally a band around it (`[low, high]` at each x, shaded in the curve's colour: a
/// spread such as a 5-95 % interval). Points with a non-finite coordinate are left out.
pub struct Series<'a> {
    pub name: &'a str,
    pub color: &'a str,
    pub dash: &'a str,
    pub x: &'a [f64],
    pub y: &'a [f64],
    pub band: Option<[&'a [f64]; 2]>,
}

impl Series<'_> {
    /// The band's points that can be drawn on `scale`, `(x, low, high)` (low and high on the
    /// scale).
    fn band_points(&self, scale: Scale) -> Vec<(f64, f64, f64)> {
        let Some([low, high]) = self.band else {
            return Vec::new();
        };
        self.x
            .iter()
            .zip(low)
            .zip(high)
            .map(|((&x, &a), &b)| (x, scale.of(a), scale.of(b)))
            .filter(|(x, a, b)| x.is_finite() && a.is_finite() && b.is_finite())
            .collect()
    }
}

/// How the y axis maps values.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Scale {
    Linear,
    /// Decades: for positive quantities spanning orders of magnitude (values <= 0 are left
    /// out).
    Log,
}

impl Scale {
    /// `v` on the scale (NaN where it cannot be drawn).
    fn of(self, v: f64) -> f64 {
        match self {
            Scale::Linear => v,
            Scale::Log if v > 0.0 => v.log10(),
            Scale::Log => f64::NAN,
        }
    }

    /// Tick positions on the scale covering `[lo, hi]` (on the scale), and their labels.
    fn ticks(self, lo: f64, hi: f64) -> Vec<(f64, String)> {
        match self {
            Scale::Linear => ticks(lo, hi)
                .into_iter()
                .map(|t| (t, fmt_tick(t)))
                .collect(),
            // nothing to draw (no value the scale can show)
            Scale::Log if !(lo.is_finite() && hi.is_finite() && lo <= hi) => Vec::new(),
            Scale::Log => {
                // 1, 2 and 5 times the powers of ten in range; the powers alone over three
                // decades or more; round values in between over less than one
                let (from, to) = (lo.floor() as i64, hi.ceil() as i64);
                let marks: &[f64] = if to - from > 3 {
                    &[1.0]
                } else {
                    &[1.0, 2.0, 5.0]
                };
                let mut at: Vec<f64> = (from..=to)
                    .take(400)
                    .flat_map(|e| {
                        marks
                            .iter()
                            .map(move |m| (m * 10f64.powi(e as i32)).log10())
                    })
                    .filter(|t| (lo..=hi).contains(t))
                    .collect();
                if at.len() < 2 {
                    at = ticks(10f64.powf(lo), 10f64.powf(hi))
                        .into_iter()
                        .filter(|v| *v > 0.0)
                        .map(f64::log10)
                        .collect();
                }
                at.into_iter()
                    .map(|t| (t, fmt_value(10f64.powf(t))))
                    .collect()
            }
        }
    }
}

/// Round tick positions covering `[lo, hi]` (about 6).
fn ticks(lo: f64, hi: f64) -> Vec<f64> {
    let span = (hi - lo).max(1e-12);
    let raw = span / 6.0;
    let mag = 10f64.powf(raw.log10().floor());
    let step = [1.0, 2.0, 2.5, 5.0, 10.0]
        .iter()
        .map(|m| m * mag)
        .find(|s| span / s <= 7.0)
        .unwrap_or(10.0 * mag);
    let first = (lo / step).ceil() * step;
    (0..)
        .map(|i| first + i as f64 * step)
        .take_while(|&v| v <= hi + 1e-9 * span)
        .collect()
}

fn escape(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
}

/// An SVG document (960 x 480 px) plotting `series` with the given title and axis labels; the
/// legend stands right of the plot, off the data.
pub fn line_plot(title: &str, xlabel: &str, ylabel: &str, series: &[Series<'_>]) -> String {
    scaled_plot(title, xlabel, ylabel, series, Scale::Linear)
}

/// As [`line_plot`], the y axis on `scale`.
pub fn scaled_plot(
    title: &str,
    xlabel: &str,
    ylabel: &str,
    series: &[Series<'_>],
    scale: Scale,
) -> String {
    let bands: Vec<Vec<(f64, f64, f64)>> = series.iter().map(|s| s.band_points(scale)).collect();
    let f = Frame::of(series, &bands, scale);
    let (w, h) = (f.w, f.h);
    let mut s = String::new();
    let _ = writeln!(
        s,
        r#"<svg xmlns="http://www.w3.org/2000/svg" width="{w}" height="{h}" viewBox="0 0 {w} {h}" font-family="sans-serif" font-size="13">"#
    );
    let _ = writeln!(s, r#"<rect width="100%" height="100%" fill="white"/>"#);
    let _ = writeln!(
        s,
        r#"<text x="{}" y="24" text-anchor="middle" font-size="16">{}</text>"#,
        w / 2.0,
        escape(title)
    );
    f.axes(scale, xlabel, ylabel, &mut s);
    f.curves(series, &bands, scale, &mut s);
    s.push_str("</svg>\n");
    s
}

/// The plot's size, margins and the data's ranges on it.
struct Frame {
    w: f64,
    h: f64,
    left: f64,
    right: f64,
    top: f64,
    bottom: f64,
    x0: f64,
    x1: f64,
    y0: f64,
    y1: f64,
}

impl Frame {
    /// The frame of `series` (with their `bands`, on `scale`): 960 x 480 px, the legend's
    /// column as wide as its longest name (about 7 px a character at 13 px), within half the
    /// width, the y range padded by 5 %.
    fn of(series: &[Series<'_>], bands: &[Vec<(f64, f64, f64)>], scale: Scale) -> Self {
        let (w, h) = (960.0, 480.0);
        let longest = series
            .iter()
            .map(|s| s.name.chars().count())
            .max()
            .unwrap_or(0);
        let right = (46.0 + 7.0 * longest as f64).clamp(180.0, w / 2.0);
        let finite = |v: &&f64| v.is_finite();
        let xs = series.iter().flat_map(|s| s.x.iter()).filter(finite);
        let (x0, x1) = xs.fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &v| {
            (a.min(v), b.max(v))
        });
        let band_ys = bands.iter().flatten().flat_map(|&(_, a, b)| [a, b]);
        let ys = series
            .iter()
            .flat_map(|s| s.y.iter().map(|&v| scale.of(v)))
            .chain(band_ys)
            .filter(|v| v.is_finite());
        let (y0, y1) = ys.fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| {
            (a.min(v), b.max(v))
        });
        let pad = 0.05 * (y1 - y0).max(1e-9);
        Self {
            w,
            h,
            left: 80.0,
            right,
            top: 40.0,
            bottom: 60.0,
            x0,
            x1,
            y0: y0 - pad,
            y1: y1 + pad,
        }
    }

    fn px(&self, x: f64) -> f64 {
        self.left
            + (x - self.x0) / (self.x1 - self.x0).max(1e-12) * (self.w - self.left - self.right)
    }

    fn py(&self, y: f64) -> f64 {
        self.top
            + (self.y1 - y) / (self.y1 - self.y0).max(1e-12) * (self.h - self.top - self.bottom)
    }

    /// The grid with its tick labels, the plot's box and the axes' labels.
    fn axes(&self, scale: Scale, xlabel: &str, ylabel: &str, s: &mut String) {
        let (w, h, left, right, top, bottom) =
            (self.w, self.h, self.left, self.right, self.top, self.bottom);
        let (x0, x1, y0, y1) = (self.x0, self.x1, self.y0, self.y1);
        let px = |x: f64| self.px(x);
        let py = |y: f64| self.py(y);
        for t in ticks(x0, x1) {
            let x = px(t);
            let _ = writeln!(
                s,
                r##"<line x1="{x:.1}" y1="{top}" x2="{x:.1}" y2="{}" stroke="#e4e4e4"/>"##,
                h - bottom
            );
            let _ = writeln!(
                s,
                r#"<text x="{x:.1}" y="{}" text-anchor="middle">{}</text>"#,
                h - bottom + 18.0,
                fmt_tick(t)
            );
        }
        for (t, label) in scale.ticks(y0, y1) {
            let y = py(t);
            let _ = writeln!(
                s,
                r##"<line x1="{left}" y1="{y:.1}" x2="{}" y2="{y:.1}" stroke="#e4e4e4"/>"##,
                w - right
            );
            let _ = writeln!(
                s,
                r#"<text x="{}" y="{:.1}" text-anchor="end">{}</text>"#,
                left - 6.0,
                y + 4.0,
                label
            );
        }
        let _ = writeln!(
            s,
            r#"<rect x="{left}" y="{top}" width="{}" height="{}" fill="none" stroke="black"/>"#,
            w - left - right,
            h - top - bottom
        );
        let _ = writeln!(
            s,
            r#"<text x="{}" y="{}" text-anchor="middle">{}</text>"#,
            (left + w - right) / 2.0,
            h - 14.0,
            escape(xlabel)
        );
        let _ = writeln!(
            s,
            r#"<text x="18" y="{}" text-anchor="middle" transform="rotate(-90 18 {})">{}</text>"#,
            (top + h - bottom) / 2.0,
            (top + h - bottom) / 2.0,
            escape(ylabel)
        );
    }

    /// The bands (first, under every curve), the curves and the legend.
    fn curves(
        &self,
        series: &[Series<'_>],
        bands: &[Vec<(f64, f64, f64)>],
        scale: Scale,
        s: &mut String,
    ) {
        let (w, right, top) = (self.w, self.right, self.top);
        let px = |x: f64| self.px(x);
        let py = |y: f64| self.py(y);
        // the bands first, under every curve
        for (se, band) in series.iter().zip(bands) {
            if band.len() >= 2 {
                let upper = band.iter().map(|&(x, _, b)| (x, b));
                let lower = band.iter().rev().map(|&(x, a, _)| (x, a));
                let pts: Vec<String> = upper
                    .chain(lower)
                    .map(|(x, y)| format!("{:.2},{:.2}", px(x), py(y)))
                    .collect();
                let _ = writeln!(
                    s,
                    r#"<polygon fill="{}" fill-opacity="0.15" stroke="none" points="{}"/>"#,
                    se.color,
                    pts.join(" ")
                );
            }
        }
        for (k, se) in series.iter().enumerate() {
            let pts: Vec<String> =
                se.x.iter()
                    .zip(se.y.iter().map(|&v| scale.of(v)))
                    .filter(|(x, y)| x.is_finite() && y.is_finite())
                    .map(|(&x, y)| format!("{:.2},{:.2}", px(x), py(y)))
                    .collect();
            let dash = if se.dash.is_empty() {
                String::new()
            } else {
                format!(r#" stroke-dasharray="{}""#, se.dash)
            };
            let _ = writeln!(
                s,
                r#"<polyline fill="none" stroke="{}" stroke-width="2"{dash} points="{}"/>"#,
                se.color,
                pts.join(" ")
            );
            let ly = top + 16.0 + 18.0 * k as f64;
            let lx = w - right + 12.0;
            let _ = writeln!(
                s,
                r#"<line x1="{lx}" y1="{ly}" x2="{}" y2="{ly}" stroke="{}" stroke-width="2"{dash}/>"#,
                lx + 28.0,
                se.color
            );
            let _ = writeln!(
                s,
                r#"<text x="{}" y="{}">{}</text>"#,
                lx + 34.0,
                ly + 4.0,
                escape(se.name)
            );
        }
    }
}

/// SVG documents of [`line_plot`] stacked into one, top to bottom.
pub fn stack(panels: &[String]) -> String {
    let (w, h) = (960.0, 480.0);
    let total = h * panels.len() as f64;
    let mut s = format!(
        r#"<svg xmlns="http://www.w3.org/2000/svg" width="{w}" height="{total}" viewBox="0 0 {w} {total}">"#
    );
    s.push('\n');
    for (i, p) in panels.iter().enumerate() {
        // each panel is a complete <svg>: nested, it is placed by its y
        let inner = p.replacen("<svg ", &format!(r#"<svg y="{}" "#, h * i as f64), 1);
        s.push_str(&inner);
    }
    s.push_str("</svg>\n");
    s
}

/// A value of a log axis: plain from 0.001 to 10^5, else in exponent form (`1e-6`).
fn fmt_value(v: f64) -> String {
    if (1e-3..1e5).contains(&v) {
        fmt_tick(v)
    } else {
        let e = v.log10().round();
        if (v / 10f64.powf(e) - 1.0).abs() < 1e-9 {
            format!("1e{e}")
        } else {
            format!("{v:.1e}")
        }
    }
}

fn fmt_tick(v: f64) -> String {
    let r = (v * 1e6).round() / 1e6;
    if r == r.trunc() && r.abs() < 1e6 {
        format!("{}", r as i64)
    } else {
        format!("{r}")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The numbers of a `points="..."` attribute, as (x, y) pairs.
    fn points(element: &str) -> Vec<(f64, f64)> {
        let list = element
            .split("points=\"")
            .nth(1)
            .unwrap()
            .split('"')
            .next()
            .unwrap();
        list.split(' ')
            .map(|p| {
                let (x, y) = p.split_once(',').unwrap();
                (x.parse().unwrap(), y.parse().unwrap())
            })
            .collect()
    }

    /// A solid black curve named `name` through `x`, `y`, with `band` shaded about it.
    fn black<'a>(
        name: &'a str,
        x: &'a [f64],
        y: &'a [f64],
        band: Option<[&'a [f64]; 2]>,
    ) -> Series<'a> {
        Series {
            name,
            color: "#000000",
            dash: "",
            x,
            y,
            band,
        }
    }

    #[test]
    fn a_band_is_shaded_under_its_curve_and_inside_the_axes() {
        let (x, y) = ([0.0, 1.0, 2.0, f64::NAN], [1.0, 2.0, 3.0, 4.0]);
        let (low, high) = ([0.5, 1.5, f64::NAN, 3.0], [1.5, 9.0, 4.0, 5.0]);
        let curve = |band| Series {
            name: "m",
            color: "#123456",
            dash: "",
            x: &x,
            y: &y,
            band,
        };
        let plot = line_plot("t", "x", "y", &[curve(Some([&low, &high]))]);
        let polygon = plot.lines().find(|l| l.starts_with("<polygon")).unwrap();
        let line = plot.lines().find(|l| l.starts_with("<polyline")).unwrap();
        // drawn before the curve, in its colour; the points with a non-finite coordinate left
        // out: x = 0 and 1, up along the highs and back along the lows
        assert!(plot.find("<polygon").unwrap() < plot.find("<polyline").unwrap());
        assert!(polygon.contains("fill=\"#123456\""));
        let band = points(polygon);
        assert_eq!(band.len(), 4);
        assert_eq!((band[0].0, band[1].0), (band[3].0, band[2].0));
        // the axes cover the band: its high of 9 is the top of the plot (480 tall, 40 above,
        // 60 below, 5 % padding), above the curve's highest point
        let (top, bottom) = (40.0, 480.0 - 60.0);
        let curve_top = points(line)
            .iter()
            .map(|p| p.1)
            .fold(f64::INFINITY, f64::min);
        let band_top = band.iter().map(|p| p.1).fold(f64::INFINITY, f64::min);
        assert!(band_top < curve_top && band_top > top && band_top < top + 0.1 * (bottom - top));
        // without a band, no polygon, and the axes fit the curve alone
        let plain = line_plot("t", "x", "y", &[curve(None)]);
        assert!(!plain.contains("<polygon"));
        let plain_top = points(plain.lines().find(|l| l.starts_with("<polyline")).unwrap())
            .iter()
            .map(|p| p.1)
            .fold(f64::INFINITY, f64::min);
        assert!(plain_top < curve_top);
    }

    #[test]
    fn a_log_axis_has_decades_and_leaves_out_what_it_cannot_draw() {
        let x = [1.0, 2.0, 3.0, 4.0, 5.0];
        let y = [0.001, 0.01, 0.0, 1.0, 10.0];
        let series = [black("m", &x, &y, None)];
        let plot = scaled_plot("t", "x", "y", &series, Scale::Log);
        // the zero left out; equal steps for equal ratios (0.001, 0.01; 1, 10)
        let line = points(plot.lines().find(|l| l.starts_with("<polyline")).unwrap());
        assert_eq!(line.len(), 4);
        let step = |a: usize, b: usize| line[a].1 - line[b].1;
        assert!((step(0, 1) - step(2, 3)).abs() < 0.02, "{line:?}");
        assert!(step(0, 1) > 0.0, "larger values higher up");
        for label in ["0.001", "0.01", "0.1", "1", "10"] {
            assert!(plot.contains(&format!(">{label}</text>")), "{label}");
        }
        // the same on a linear axis keeps the zero
        let linear = line_plot("t", "x", "y", &series);
        let line = points(linear.lines().find(|l| l.starts_with("<polyline")).unwrap());
        assert_eq!(line.len(), 5);
        // labels of a log axis
        assert_eq!(fmt_value(1e-6), "1e-6");
        assert_eq!(fmt_value(1e7), "1e7");
        assert_eq!(fmt_value(0.02), "0.02");
        assert!(Scale::Log.of(-1.0).is_nan());
        // within one decade: 1, 2 and 5 times its powers
        let labels: Vec<String> = Scale::Log
            .ticks(0.5f64.log10(), 6f64.log10())
            .into_iter()
            .map(|t| t.1)
            .collect();
        assert_eq!(labels, ["0.5", "1", "2", "5"]);
    }

    #[test]
    fn the_legend_is_as_wide_as_its_longest_name() {
        let (x, y) = ([0.0, 1.0], [0.0, 1.0]);
        let name = "direct: globally linearised, median of 5 (range shaded)";
        let series = |name| black(name, &x, &y, None);
        // the name's text starts far enough left for about 7 px a character
        let start = |plot: &str| -> f64 {
            let text = plot.lines().rfind(|l| l.starts_with("<text x=")).unwrap();
            text["<text x=\"".len()..]
                .split('"')
                .next()
                .unwrap()
                .parse()
                .unwrap()
        };
        let long = line_plot("t", "x", "y", &[series(name)]);
        assert!(start(&long) + 7.0 * name.len() as f64 <= 960.0 + 1e-9);
        // a short one keeps the usual 180 px column
        assert_eq!(
            start(&line_plot("t", "x", "y", &[series("m")])),
            960.0 - 180.0 + 46.0
        );
    }

    #[test]
    fn a_log_axis_with_nothing_to_draw_is_an_empty_plot() {
        let (x, y) = ([0.0, 1.0], [0.0, f64::NAN]);
        let series = [black("m", &x, &y, Some([&y, &y]))];
        let plot = scaled_plot("t", "x", "y", &series, Scale::Log);
        assert!(plot.starts_with("<svg") && plot.ends_with("</svg>\n"));
        assert!(!plot.contains("<polygon"));
        assert!(Scale::Log
            .ticks(f64::INFINITY, f64::NEG_INFINITY)
            .is_empty());
    }
}
