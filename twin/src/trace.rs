//! The sensor trace: what the MCU sees at 10 kHz next to the truth, in one documented CSV
//! format (docs/trace-format.md) with a writer and a reader whose errors name the line and
//! column. The monitor tests, the benchmarks and the firmware replay all read this format.
//!
//! ```text
//! # noback-trace v1
//! # sample_rate_hz=10000
//! t_s,current_code,motor_count,output_count,drive_on,pressing_force_n,braking_torque_nm,output_speed_rad_s,input_speed_rad_s,output_angle_rad,brake_state,current_command_code
//! 0.0000,2048,0,0,1,169.2,8.43,-13.78,-13.78,0,1,2048
//! ```
//!
//! The last column, the drive's current command, is optional: a trace without it (an ECU that
//! does not log it) reads with `current_command_code = None`.

use std::io::Write;

/// The first line of every trace file.
pub const HEADER: &str = "# noback-trace v1";

/// The column names, in order; the last ([`COMMAND_COLUMN`]) may be absent.
pub const COLUMNS: [&str; 12] = [
    "t_s",
    "current_code",
    "motor_count",
    "output_count",
    "drive_on",
    "pressing_force_n",
    "braking_torque_nm",
    "output_speed_rad_s",
    "input_speed_rad_s",
    "output_angle_rad",
    "brake_state",
    COMMAND_COLUMN,
];

/// The optional last column: the drive's current command as the ADC code an ideal sensor would
/// read for it (offset binary).
pub const COMMAND_COLUMN: &str = "current_command_code";

/// One row: the raw readings and the truth at one sample.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct TraceRow {
    /// Time (s).
    pub t_s: f64,
    /// Motor phase-current ADC code (offset binary).
    pub current_code: u16,
    /// Motor-encoder counter value (wraps modulo 2^counter bits).
    pub motor_count: u32,
    /// Output absolute-encoder reading (wraps modulo 2^bits).
    pub output_count: u32,
    /// Drive commanded on.
    pub drive_on: bool,
    /// Truth: pack pressing force (N).
    pub pressing_force_n: f64,
    /// Truth: braking torque magnitude (N·m).
    pub braking_torque_nm: f64,
    /// Truth: output speed (rad/s, positive = load direction).
    pub output_speed_rad_s: f64,
    /// Truth: input speed (rad/s).
    pub input_speed_rad_s: f64,
    /// Truth: output angle (rad).
    pub output_angle_rad: f64,
    /// Truth: 0 released, 1 slipping, 2 locked.
    pub brake_state: u8,
    /// The drive's current command (ADC code of an ideal sensor), if logged.
    pub current_command_code: Option<u16>,
}

/// A whole trace.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Trace {
    /// Sample rate (Hz).
    pub sample_rate_hz: f64,
    /// Rows in time order.
    pub rows: Vec<TraceRow>,
}

/// Why a trace could not be read.
#[derive(Debug)]
pub enum TraceError {
    /// The file could not be read or written.
    Io(std::io::Error),
    /// The content is malformed at `line` (1-based), `column` (1-based CSV field, 0 = line).
    Parse {
        /// Line number.
        line: usize,
        /// Field number.
        column: usize,
        /// What is wrong.
        message: String,
    },
}

impl std::fmt::Display for TraceError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            TraceError::Io(e) => write!(f, "trace i/o: {e}"),
            TraceError::Parse {
                line,
                column,
                message,
            } => write!(f, "trace line {line}, column {column}: {message}"),
        }
    }
}

impl std::error::Error for TraceError {}

impl From<std::io::Error> for TraceError {
    fn from(e: std::io::Error) -> Self {
        TraceError::Io(e)
    }
}

fn parse_err(line: usize, column: usize, message: impl Into<String>) -> TraceError {
    TraceError::Parse {
        line,
        column,
        message: message.into(),
    }
}

impl Trace {
    /// Write the trace in the v1 CSV format (the command column when every row has one).
    pub fn write_to(&self, w: &mut dyn Write) -> Result<(), TraceError> {
        let command = self.rows.iter().all(|r| r.current_command_code.is_some());
        let columns = if command {
            &COLUMNS[..]
        } else {
            &COLUMNS[..COLUMNS.len() - 1]
        };
        writeln!(w, "{HEADER}")?;
        writeln!(w, "# sample_rate_hz={}", self.sample_rate_hz)?;
        writeln!(w, "{}", columns.join(","))?;
        for r in &self.rows {
            write!(
                w,
                "{:.4},{},{},{},{},{:.3},{:.4},{:.6},{:.6},{:.7},{}",
                r.t_s,
                r.current_code,
                r.motor_count,
                r.output_count,
                u8::from(r.drive_on),
                r.pressing_force_n,
                r.braking_torque_nm,
                r.output_speed_rad_s,
                r.input_speed_rad_s,
                r.output_angle_rad,
                r.brake_state
            )?;
            match r.current_command_code {
                Some(c) if command => writeln!(w, ",{c}")?,
                _ => writeln!(w)?,
            }
        }
        Ok(())
    }

    /// Write to a file.
    pub fn write(&self, path: &std::path::Path) -> Result<(), TraceError> {
        let mut f = std::io::BufWriter::new(std::fs::File::create(path)?);
        self.write_to(&mut f)?;
        f.flush()?;
        Ok(())
    }

    /// Read a trace file.
    pub fn read(path: &std::path::Path) -> Result<Trace, TraceError> {
        let text = std::fs::read_to_string(path)?;
        Trace::parse(&text)
    }

    /// Parse the text of a trace.
    pub fn parse(text: &str) -> Result<Trace, TraceError> {
        let mut lines = text.lines().enumerate().map(|(i, l)| (i + 1, l));
        match lines.next() {
            Some((_, l)) if l.trim_end() == HEADER => {}
            Some((n, l)) => {
                return Err(parse_err(
                    n,
                    0,
                    format!(
                        "expected `{HEADER}`, found `{}`",
                        l.chars().take(40).collect::<String>()
                    ),
                ))
            }
            None => return Err(parse_err(1, 0, "empty file")),
        }
        let mut trace = Trace {
            sample_rate_hz: 0.0,
            rows: Vec::new(),
        };
        let mut header_seen = false;
        let mut with_command = false;
        let mut rate_line = None;
        let mut header_line = 1;
        for (n, line) in lines {
            let line = line.trim_end();
            if line.is_empty() {
                continue;
            }
            if let Some(meta) = line.strip_prefix('#') {
                if let Some(v) = meta.trim().strip_prefix("sample_rate_hz=") {
                    let rate: f64 = v.trim().parse().unwrap_or(f64::NAN);
                    if !(rate.is_finite() && rate > 0.0) {
                        return Err(parse_err(
                            n,
                            0,
                            format!(
                                "sample_rate_hz must be a positive number, found `{}`",
                                crate::args::short(v.trim())
                            ),
                        ));
                    }
                    trace.sample_rate_hz = rate;
                    rate_line = Some(n);
                }
                continue;
            }
            if !header_seen {
                let cols: Vec<&str> = line.split(',').collect();
                with_command = cols.len() == COLUMNS.len();
                let expected = &COLUMNS[..COLUMNS.len() - usize::from(!with_command)];
                if cols != expected {
                    let col = cols
                        .iter()
                        .zip(COLUMNS.iter())
                        .position(|(a, b)| a != b)
                        .unwrap_or(cols.len().min(COLUMNS.len()));
                    return Err(parse_err(
                        n,
                        col + 1,
                        format!("expected columns `{}`", COLUMNS.join(",")),
                    ));
                }
                header_seen = true;
                header_line = n;
                continue;
            }
            let row = parse_row(n, line, with_command)?;
            if let Some(last) = trace.rows.last() {
                if row.t_s <= last.t_s {
                    return Err(parse_err(
                        n,
                        1,
                        format!(
                            "time does not increase: t_s = {} after {}",
                            crate::args::num(row.t_s),
                            crate::args::num(last.t_s)
                        ),
                    ));
                }
            }
            trace.rows.push(row);
        }
        if !header_seen {
            return Err(parse_err(1, 0, "no column header line"));
        }
        if rate_line.is_none() {
            return Err(parse_err(2, 0, "missing `# sample_rate_hz=` line"));
        }
        match trace.rows.len() {
            0 => Err(parse_err(
                header_line + 1,
                0,
                "no samples after the column header",
            )),
            1 => Err(parse_err(
                header_line + 1,
                0,
                "one sample: a trace needs at least two",
            )),
            _ => Ok(trace),
        }
    }
}

fn parse_row(n: usize, line: &str, with_command: bool) -> Result<TraceRow, TraceError> {
    let f: Vec<&str> = line.split(',').collect();
    let fields = COLUMNS.len() - usize::from(!with_command);
    if f.len() != fields {
        return Err(parse_err(
            n,
            f.len().min(fields) + 1,
            format!("expected {fields} fields, found {}", f.len()),
        ));
    }
    let field = |i: usize| f.get(i).copied().unwrap_or("").trim();
    let float = |i: usize| -> Result<f64, TraceError> {
        let v: f64 = field(i).parse().map_err(|_| {
            parse_err(
                n,
                i + 1,
                format!(
                    "`{}` is not a number ({})",
                    crate::args::short(field(i)),
                    COLUMNS.get(i).unwrap_or(&"")
                ),
            )
        })?;
        if v.is_finite() {
            Ok(v)
        } else {
            Err(parse_err(n, i + 1, "not finite"))
        }
    };
    let int = |i: usize| -> Result<u32, TraceError> {
        field(i).parse().map_err(|_| {
            parse_err(
                n,
                i + 1,
                format!(
                    "`{}` is not an unsigned integer ({})",
                    crate::args::short(field(i)),
                    COLUMNS.get(i).unwrap_or(&"")
                ),
            )
        })
    };
    let code16 = |i: usize| {
        u16::try_from(int(i)?).map_err(|_| parse_err(n, i + 1, "current code over 65535"))
    };
    let current_code = code16(1)?;
    let current_command_code = if with_command {
        Some(code16(11)?)
    } else {
        None
    };
    let drive = int(4)?;
    if drive > 1 {
        return Err(parse_err(n, 5, "drive_on must be 0 or 1"));
    }
    let state = int(10)?;
    if state > 2 {
        return Err(parse_err(n, 11, "brake_state must be 0, 1 or 2"));
    }
    Ok(TraceRow {
        t_s: float(0)?,
        current_code,
        motor_count: int(2)?,
        output_count: int(3)?,
        drive_on: drive == 1,
        pressing_force_n: float(5)?,
        braking_torque_nm: float(6)?,
        output_speed_rad_s: float(7)?,
        input_speed_rad_s: float(8)?,
        output_angle_rad: float(9)?,
        brake_state: state as u8,
        current_command_code,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sample() -> Trace {
        Trace {
            sample_rate_hz: 10_000.0,
            rows: vec![
                TraceRow {
                    t_s: 0.0,
                    current_code: 2048,
                    motor_count: 65535,
                    output_count: 16383,
                    drive_on: true,
                    pressing_force_n: 169.2,
                    braking_torque_nm: 8.43,
                    output_speed_rad_s: -13.78,
                    input_speed_rad_s: -13.78,
                    output_angle_rad: 0.0,
                    brake_state: 1,
                    current_command_code: None,
                },
                TraceRow {
                    t_s: 0.0001,
                    brake_state: 2,
                    ..TraceRow::default()
                },
            ],
        }
    }

    #[test]
    fn round_trip() {
        let t = sample();
        let mut buf = Vec::new();
        t.write_to(&mut buf).unwrap();
        let text = String::from_utf8(buf).unwrap();
        let back = Trace::parse(&text).unwrap();
        assert_eq!(back.rows.len(), 2);
        assert_eq!(back.rows[0].motor_count, 65535);
        assert_eq!(back.rows[0].current_code, 2048);
        assert!((back.rows[0].pressing_force_n - 169.2).abs() < 1e-9);
        assert_eq!(back.sample_rate_hz, 10_000.0);
        assert_eq!(back.rows[0].current_command_code, None);
    }

    #[test]
    fn the_command_column_round_trips_when_every_row_has_it() {
        let mut t = sample();
        for (r, c) in t.rows.iter_mut().zip([2100, 1990]) {
            r.current_command_code = Some(c);
        }
        let mut buf = Vec::new();
        t.write_to(&mut buf).unwrap();
        let text = String::from_utf8(buf).unwrap();
        assert!(
            text.contains(",brake_state,current_command_code\n"),
            "{text}"
        );
        let back = Trace::parse(&text).unwrap();
        assert_eq!(back.rows[1].current_command_code, Some(1990));
        let missing = text.replace(",1990\n", "\n");
        assert!(matches!(
            Trace::parse(&missing),
            Err(TraceError::Parse { line: 5, .. })
        ));
    }

    #[test]
    fn errors_name_line_and_column() {
        let t = sample();
        let mut buf = Vec::new();
        t.write_to(&mut buf).unwrap();
        let text = String::from_utf8(buf).unwrap().replace("65535", "x");
        match Trace::parse(&text) {
            Err(TraceError::Parse { line, column, .. }) => assert_eq!((line, column), (4, 3)),
            other => panic!("{other:?}"),
        }
        match Trace::parse("# noback-trace v0\n") {
            Err(TraceError::Parse { line, column, .. }) => assert_eq!((line, column), (1, 0)),
            other => panic!("{other:?}"),
        }
        let short = String::from_utf8({
            let mut b = Vec::new();
            t.write_to(&mut b).unwrap();
            b
        })
        .unwrap()
        .replace(",1\n0.0001", ",1,9\n0.0001");
        match Trace::parse(&short) {
            Err(TraceError::Parse { line, .. }) => assert_eq!(line, 4),
            other => panic!("{other:?}"),
        }
    }

    #[test]
    fn a_trace_that_cannot_be_compared_is_refused_naming_why() {
        let cols = COLUMNS[..COLUMNS.len() - 1].join(",");
        let row = |t: &str| format!("{t},2048,0,0,0,0,0,0,0,0,0\n");
        let text = |rate: &str, rows: &[&str]| {
            let body: String = rows.iter().map(|t| row(t)).collect();
            format!("{HEADER}\n{rate}{cols}\n{body}")
        };
        let err = |t: String| match Trace::parse(&t) {
            Err(TraceError::Parse { line, message, .. }) => (line, message),
            other => panic!("{other:?}"),
        };
        let rate = "# sample_rate_hz=10000\n";
        let (line, m) = err(text(rate, &[]));
        assert!(line == 4 && m.contains("no samples"), "{m}");
        let (line, m) = err(text(rate, &["0.0"]));
        assert!(line == 4 && m.contains("one sample"), "{m}");
        let (line, m) = err(text(rate, &["0.0", "0.0002", "0.0001"]));
        assert!(line == 6 && m.contains("time does not increase"), "{m}");
        let (line, m) = err(text("# sample_rate_hz=0\n", &["0.0", "0.0001"]));
        assert!(
            line == 2 && m.contains("sample_rate_hz must be a positive number"),
            "{m}"
        );
        let (_, m) = err(text("", &["0.0", "0.0001"]));
        assert!(m.contains("missing `# sample_rate_hz=`"), "{m}");
        assert!(Trace::parse(&text(rate, &["0.0", "0.0001"])).is_ok());
    }
}
