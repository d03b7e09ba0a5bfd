//! A hand-written SVG time-history plot (stacked panels, shared time axis). Written by hand:
//! `plotters` even without default features pulls a font stack; a polyline chart needs none.

use std::fmt::Write;

/// One curve.
pub struct Series<'a> {
    /// Legend label.
    pub label: &'a str,
    /// Stroke colour.
    pub color: &'a str,
    /// Values, one per time point.
    pub values: Vec<f64>,
}

/// One panel: a y-axis label and its curves.
pub struct Panel<'a> {
    /// Axis label with unit.
    pub title: &'a str,
    /// Curves.
    pub series: Vec<Series<'a>>,
}

const W: f64 = 900.0;
const PANEL_H: f64 = 150.0;
const LEFT: f64 = 70.0;
const RIGHT: f64 = 20.0;
const TOP: f64 = 30.0;
const GAP: f64 = 30.0;

/// Render panels over the time points `t_s` (decimated to at most 1500 points per curve).
pub fn render(title: &str, t_s: &[f64], panels: &[Panel<'_>]) -> String {
    render_xy(title, "s", t_s, panels)
}

/// Render panels over a shared x axis with unit `x_unit`.
pub fn render_xy(title: &str, x_unit: &str, t_s: &[f64], panels: &[Panel<'_>]) -> String {
    let n = t_s.len();
    let stride = (n / 1500).max(1);
    let idx: Vec<usize> = (0..n).step_by(stride).collect();
    let (t0, t1) = match (t_s.first(), t_s.last()) {
        (Some(a), Some(b)) if b > a => (*a, *b),
        _ => (0.0, 1.0),
    };
    let height = TOP + panels.len() as f64 * (PANEL_H + GAP) + 20.0;
    let mut s = String::new();
    let _ = writeln!(
        s,
        r#"<svg xmlns="http://www.w3.org/2000/svg" width="{W}" height="{height}" font-family="sans-serif" font-size="11">"#
    );
    let _ = writeln!(s, r#"<rect width="100%" height="100%" fill="white"/>"#);
    let _ = writeln!(
        s,
        r#"<text x="{LEFT}" y="18" font-size="14">{}</text>"#,
        escape(title)
    );
    let pw = W - LEFT - RIGHT;
    for (p, panel) in panels.iter().enumerate() {
        let y0 = TOP + p as f64 * (PANEL_H + GAP);
        let mut lo = f64::INFINITY;
        let mut hi = f64::NEG_INFINITY;
        for ser in &panel.series {
            for v in ser.values.iter().filter(|v| v.is_finite()) {
                lo = lo.min(*v);
                hi = hi.max(*v);
            }
        }
        if !lo.is_finite() {
            lo = 0.0;
            hi = 1.0;
        }
        if hi - lo < 1e-12 {
            hi = lo + 1.0;
        }
        let _ = writeln!(
            s,
            r##"<rect x="{LEFT}" y="{y0}" width="{pw}" height="{PANEL_H}" fill="none" stroke="#999"/>"##
        );
        let _ = writeln!(
            s,
            r#"<text x="4" y="{}">{}</text>"#,
            y0 + 12.0,
            escape(panel.title)
        );
        let _ = writeln!(s, r#"<text x="4" y="{}">{}</text>"#, y0 + 28.0, fmt(hi));
        let _ = writeln!(s, r#"<text x="4" y="{}">{}</text>"#, y0 + PANEL_H, fmt(lo));
        if lo < 0.0 && hi > 0.0 {
            let yz = y0 + PANEL_H * (hi / (hi - lo));
            let _ = writeln!(
                s,
                r##"<line x1="{LEFT}" y1="{yz:.1}" x2="{:.1}" y2="{yz:.1}" stroke="#ddd"/>"##,
                LEFT + pw
            );
        }
        for (k, ser) in panel.series.iter().enumerate() {
            let mut pts = String::new();
            for &i in &idx {
                let (Some(t), Some(v)) = (t_s.get(i), ser.values.get(i)) else {
                    continue;
                };
                if !v.is_finite() {
                    continue;
                }
                let x = LEFT + pw * (t - t0) / (t1 - t0);
                let y = y0 + PANEL_H * (hi - v) / (hi - lo);
                let _ = write!(pts, "{x:.1},{y:.1} ");
            }
            let _ = writeln!(
                s,
                r#"<polyline fill="none" stroke="{}" stroke-width="1.2" points="{}"/>"#,
                ser.color,
                pts.trim_end()
            );
            let _ = writeln!(
                s,
                r#"<text x="{:.1}" y="{:.1}" fill="{}">{}</text>"#,
                LEFT + pw - 200.0 + 0.0 * k as f64,
                y0 + 14.0 + 13.0 * k as f64,
                ser.color,
                escape(ser.label)
            );
        }
    }
    let yb = TOP + panels.len() as f64 * (PANEL_H + GAP) - GAP + 14.0;
    let _ = writeln!(
        s,
        r#"<text x="{LEFT}" y="{yb}">{} {}</text>"#,
        fmt(t0),
        escape(x_unit)
    );
    let _ = writeln!(
        s,
        r#"<text x="{}" y="{yb}" text-anchor="end">{} {}</text>"#,
        W - RIGHT,
        fmt(t1),
        escape(x_unit)
    );
    let _ = writeln!(s, "</svg>");
    s
}

fn fmt(v: f64) -> String {
    if v.abs() >= 1000.0 || (v != 0.0 && v.abs() < 0.01) {
        format!("{v:.3e}")
    } else {
        format!("{v:.3}")
    }
}

fn escape(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn renders_a_well_formed_document() {
        let t = vec![0.0, 0.5, 1.0];
        let svg = render(
            "x < y",
            &t,
            &[Panel {
                title: "speed (rad/s)",
                series: vec![Series {
                    label: "output",
                    color: "blue",
                    values: vec![-1.0, 0.0, 2.0],
                }],
            }],
        );
        assert!(svg.starts_with("<svg") && svg.trim_end().ends_with("</svg>"));
        assert!(svg.contains("x &lt; y"));
        assert!(svg.contains("<polyline"));
    }
}
