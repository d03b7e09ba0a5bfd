//! Time-history and sweep charts as SVG through `plotters`: stacked panels over a shared x axis,
//! one y axis per panel, a legend per panel, engineering notation on the axes.

use plotters::prelude::*;

/// One curve.
pub struct Series<'a> {
    /// Legend label.
    pub label: &'a str,
    /// Stroke colour: `#rgb`, `#rrggbb` or a basic name (black, blue, red, green, grey).
    pub color: &'a str,
    /// Values, one per x point.
    pub values: Vec<f64>,
}

/// One panel: a y-axis label and its curves.
pub struct Panel<'a> {
    /// Axis label with unit.
    pub title: &'a str,
    /// Curves.
    pub series: Vec<Series<'a>>,
}

const W: u32 = 900;
const PANEL_H: u32 = 190;
const TITLE_H: u32 = 30;
/// Points per curve at most (a longer history is decimated by a stride).
const MAX_POINTS: usize = 1500;

/// Render panels over the time points `t_s` (decimated to at most 1500 points per curve).
pub fn render(title: &str, t_s: &[f64], panels: &[Panel<'_>]) -> String {
    render_xy(title, "s", t_s, panels)
}

/// Render panels over a shared x axis with unit `x_unit`.
pub fn render_xy(title: &str, x_unit: &str, x: &[f64], panels: &[Panel<'_>]) -> String {
    let mut out = String::new();
    let height = TITLE_H + PANEL_H * panels.len().max(1) as u32;
    // Drawing into a String cannot fail but for a plotters bug; an empty chart says so.
    if let Err(e) = draw(&mut out, (W, height), title, x_unit, x, panels) {
        return format!(
            r#"<svg xmlns="http://www.w3.org/2000/svg" width="{W}" height="40"><text x="10" y="20">chart failed: {}</text></svg>"#,
            escape(&e)
        );
    }
    out
}

fn draw(
    out: &mut String,
    size: (u32, u32),
    title: &str,
    x_unit: &str,
    x: &[f64],
    panels: &[Panel<'_>],
) -> Result<(), String> {
    let e = |err: DrawingAreaErrorKind<_>| format!("{err:?}");
    let root = SVGBackend::with_string(out, size).into_drawing_area();
    root.fill(&WHITE).map_err(e)?;
    let root = root.titled(title, ("sans-serif", 16)).map_err(e)?;
    let stride = (x.len() / MAX_POINTS).max(1);
    let (x0, x1) = range(x.iter().copied());
    let areas = root.split_evenly((panels.len().max(1), 1));
    for (k, (panel, area)) in panels.iter().zip(&areas).enumerate() {
        let (y0, y1) = range(panel.series.iter().flat_map(|s| s.values.iter().copied()));
        let mut c = ChartBuilder::on(area)
            .margin(6)
            .x_label_area_size(if k + 1 == panels.len() { 34 } else { 18 })
            .y_label_area_size(64)
            .build_cartesian_2d(x0..x1, y0..y1)
            .map_err(e)?;
        let (xs, ys) = (x1 - x0, y1 - y0);
        let (fx, fy) = (|v: &f64| tick(*v, xs), |v: &f64| tick(*v, ys));
        let mut mesh = c.configure_mesh();
        mesh.y_desc(panel.title)
            .x_label_formatter(&fx)
            .y_label_formatter(&fy)
            .light_line_style(WHITE);
        if k + 1 == panels.len() {
            mesh.x_desc(x_unit);
        }
        mesh.draw().map_err(e)?;
        for s in &panel.series {
            let col = colour(s.color);
            let pts = x
                .iter()
                .zip(&s.values)
                .step_by(stride)
                .filter(|(a, b)| a.is_finite() && b.is_finite())
                .map(|(a, b)| (*a, *b));
            c.draw_series(LineSeries::new(pts, col.stroke_width(1)))
                .map_err(e)?
                .label(s.label)
                .legend(move |(lx, ly)| PathElement::new([(lx, ly), (lx + 16, ly)], col));
        }
        c.configure_series_labels()
            .position(SeriesLabelPosition::UpperRight)
            .background_style(WHITE.mix(0.85))
            .border_style(BLACK.mix(0.4))
            .draw()
            .map_err(e)?;
    }
    root.present().map_err(e)
}

/// A tick label: plain decimals from 0.001 to 9 999 (the unit is in the axis title, where an SI
/// prefix on "mm" would mislead), engineering notation beyond; 0 for rounding residue.
fn tick(v: f64, span: f64) -> String {
    let a = v.abs();
    if a <= 1e-9 * span {
        return "0".into();
    }
    if !(1e-3..1e4).contains(&a) {
        return eng(v);
    }
    let decimals = (2 - a.log10().floor() as i32).max(0) as usize;
    let s = format!("{v:.decimals$}");
    if s.contains('.') {
        s.trim_end_matches('0').trim_end_matches('.').to_string()
    } else {
        s
    }
}

/// The finite span of `values`, widened when it is empty or flat.
fn range(values: impl Iterator<Item = f64>) -> (f64, f64) {
    let (lo, hi) = values
        .filter(|v| v.is_finite())
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| {
            (a.min(v), b.max(v))
        });
    if !lo.is_finite() {
        return (0.0, 1.0);
    }
    let pad = ((hi - lo) * 0.05).max(1e-9 * lo.abs().max(1.0));
    (lo - pad, hi + pad)
}

/// A stroke colour from `#rgb`, `#rrggbb` or a basic name; anything else is black.
fn colour(c: &str) -> RGBColor {
    let hex = |s: &str| u8::from_str_radix(s, 16).ok();
    let digits = c.strip_prefix('#').unwrap_or("");
    let rgb = match digits.len() {
        3 => digits
            .get(0..1)
            .zip(digits.get(1..2))
            .zip(digits.get(2..3))
            .and_then(|((r, g), b)| Some((hex(r)? * 17, hex(g)? * 17, hex(b)? * 17))),
        6 => digits
            .get(0..2)
            .zip(digits.get(2..4))
            .zip(digits.get(4..6))
            .and_then(|((r, g), b)| Some((hex(r)?, hex(g)?, hex(b)?))),
        _ => match c {
            "blue" => Some((0, 0, 255)),
            "red" => Some((255, 0, 0)),
            "green" => Some((0, 128, 0)),
            "grey" | "gray" => Some((128, 128, 128)),
            _ => None,
        },
    };
    let (r, g, b) = rgb.unwrap_or((0, 0, 0));
    RGBColor(r, g, b)
}

/// `v` in engineering notation with an SI prefix (`2.5 m`, `100 k`, `1 M`).
pub fn eng(v: f64) -> String {
    if v == 0.0 || !v.is_finite() {
        return format!("{v}");
    }
    const P: [(f64, &str); 9] = [
        (1e12, "T"),
        (1e9, "G"),
        (1e6, "M"),
        (1e3, "k"),
        (1.0, ""),
        (1e-3, "m"),
        (1e-6, "µ"),
        (1e-9, "n"),
        (1e-12, "p"),
    ];
    let a = v.abs() * (1.0 + 1e-9);
    let (scale, prefix) = P
        .iter()
        .copied()
        .find(|(s, _)| a >= *s)
        .unwrap_or((1e-12, "p"));
    let m = v / scale;
    let digits = if m.abs() >= 100.0 {
        0
    } else if m.abs() >= 10.0 {
        1
    } else {
        2
    };
    let s = format!("{m:.digits$}");
    let s = if s.contains('.') {
        s.trim_end_matches('0').trim_end_matches('.').to_string()
    } else {
        s
    };
    format!("{s}{}{prefix}", if prefix.is_empty() { "" } else { " " })
}

/// `v` with a unit in engineering notation (`715 mN·m`, `2.57 N·m`).
pub fn eng_unit(v: f64, unit: &str) -> String {
    let e = eng(v);
    if e.contains(' ') {
        format!("{e}{unit}")
    } else {
        format!("{e} {unit}")
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
                    color: "#06c",
                    values: vec![-1.0, 0.0, 2.0],
                }],
            }],
        );
        assert!(svg.starts_with("<svg"), "{svg}");
        assert!(svg.trim_end().ends_with("</svg>"));
        assert!(svg.contains("x &lt; y"), "{svg}");
        assert!(svg.contains("<polyline"), "{svg}");
        assert!(svg.contains("#0066CC") || svg.contains("#0066cc"), "{svg}");
    }

    #[test]
    fn colours_and_notation() {
        assert_eq!(colour("#c00"), RGBColor(204, 0, 0));
        assert_eq!(colour("#1f77b4"), RGBColor(31, 119, 180));
        assert_eq!(colour("nonsense"), RGBColor(0, 0, 0));
        assert_eq!(eng(1_000_000.0), "1 M");
        assert_eq!(eng(2.5e-3), "2.5 m");
        assert_eq!(eng(8.524e6), "8.52 M");
        assert_eq!(eng(150_000.0), "150 k");
        assert_eq!(eng(-0.25), "-250 m");
        assert_eq!(tick(0.7, 1.0), "0.7");
        assert_eq!(tick(-2.5, 3.0), "-2.5");
        assert_eq!(tick(25_000.0, 3e4), "25 k");
        assert_eq!(tick(-1e-13, 1.0), "0");
        assert_eq!(tick(0.0123, 0.1), "0.0123");
        assert_eq!(eng(3.0), "3");
        assert_eq!(eng_unit(0.715, "N·m"), "715 mN·m");
        assert_eq!(eng_unit(2.57, "N·m"), "2.57 N·m");
    }
}
