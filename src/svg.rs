//! Minimal SVG line plots (no dependencies): axes with round-number ticks, one polyline per
//! series, a legend. Opens in any browser.

use std::fmt::Write;

/// One curve: a name for the legend, a CSS colour, a dash pattern (`""` for solid), x and y.
pub struct Series<'a> {
    pub name: &'a str,
    pub color: &'a str,
    pub dash: &'a str,
    pub x: &'a [f64],
    pub y: &'a [f64],
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
    let (w, h) = (960.0, 480.0);
    let (left, right, top, bottom) = (80.0, 180.0, 40.0, 60.0);
    let finite = |v: &&f64| v.is_finite();
    let xs = series.iter().flat_map(|s| s.x.iter()).filter(finite);
    let (x0, x1) = xs.fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &v| {
        (a.min(v), b.max(v))
    });
    let ys = series.iter().flat_map(|s| s.y.iter()).filter(finite);
    let (mut y0, mut y1) = ys.fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &v| {
        (a.min(v), b.max(v))
    });
    let pad = 0.05 * (y1 - y0).max(1e-9);
    y0 -= pad;
    y1 += pad;
    let px = |x: f64| left + (x - x0) / (x1 - x0).max(1e-12) * (w - left - right);
    let py = |y: f64| top + (y1 - y) / (y1 - y0).max(1e-12) * (h - top - bottom);
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
    for t in ticks(y0, y1) {
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
            fmt_tick(t)
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
    for (k, se) in series.iter().enumerate() {
        let pts: Vec<String> =
            se.x.iter()
                .zip(se.y)
                .filter(|(x, y)| x.is_finite() && y.is_finite())
                .map(|(&x, &y)| format!("{:.2},{:.2}", px(x), py(y)))
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
    s.push_str("</svg>\n");
    s
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

fn fmt_tick(v: f64) -> String {
    let r = (v * 1e6).round() / 1e6;
    if r == r.trunc() && r.abs() < 1e6 {
        format!("{}", r as i64)
    } else {
        format!("{r}")
    }
}
