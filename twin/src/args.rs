//! The command-line convention every `cargo xtask` command keeps (the twin's and the xtask's):
//! clap parses; `--help` prints and exits 0; a bad argument prints ONE line naming it on stderr
//! and exits [`EXIT_USAGE`]; values echoed in messages are cut to a readable length.

use clap::error::ErrorKind;

/// Exit code of a usage or input error (bad flag, bad value, bad scene or trace file).
pub const EXIT_USAGE: i32 = 2;

/// Longest value echoed in a message, in characters (longer ones end in `…`).
pub const ECHO_CHARS: usize = 80;

/// `s` cut to [`ECHO_CHARS`] characters, with `…` when cut.
pub fn short(s: &str) -> String {
    match s.char_indices().nth(ECHO_CHARS) {
        Some((at, _)) => format!("{}…", &s[..at]),
        None => s.to_string(),
    }
}

/// An internal error's text kept readable: each line cut to 240 characters, at most 12 lines.
pub fn capped(text: &str) -> String {
    let mut lines: Vec<String> = text
        .lines()
        .take(12)
        .map(|l| match l.char_indices().nth(240) {
            Some((at, _)) => format!("{}…", &l[..at]),
            None => l.to_string(),
        })
        .collect();
    if text.lines().count() > 12 {
        lines.push("…".into());
    }
    lines.join("\n")
}

/// A number as a reader wants it: plain in [1e-4, 1e6), exponent form outside (1e308 is
/// `1e308`, not 309 digits).
pub fn num(v: f64) -> String {
    let a = v.abs();
    if v == 0.0 || !v.is_finite() || (1e-4..1e6).contains(&a) {
        format!("{v}")
    } else {
        format!("{v:e}")
    }
}

/// Parses `args` (without the program name) for command `prog` (as in `cargo xtask PROG`).
/// `Err(code)` means the caller exits with `code`: 0 after `--help`, [`EXIT_USAGE`] after a
/// bad argument, whose one-line message is already printed.
pub fn parse<T: clap::Parser>(prog: &str, args: &[String]) -> Result<T, i32> {
    let argv0 = if prog.is_empty() {
        "cargo xtask".to_string()
    } else {
        format!("cargo xtask {prog}")
    };
    let argv = std::iter::once(argv0).chain(args.iter().cloned());
    T::try_parse_from(argv).map_err(|e| report(prog, &e))
}

/// Prints a clap outcome by the convention and returns the exit code.
pub fn report(prog: &str, e: &clap::Error) -> i32 {
    match e.kind() {
        ErrorKind::DisplayHelp | ErrorKind::DisplayVersion => {
            print!("{}", e.render());
            0
        }
        ErrorKind::DisplayHelpOnMissingArgumentOrSubcommand => {
            eprintln!(
                "{}: error: a command is required (see `cargo xtask --help`)",
                label(prog)
            );
            EXIT_USAGE
        }
        _ => {
            eprintln!("{}", one_line(prog, e));
            EXIT_USAGE
        }
    }
}

/// The first line of a clap error, values shortened, naming the command and where help is.
pub fn one_line(prog: &str, e: &clap::Error) -> String {
    let text = e.render().to_string();
    let first = text.lines().next().unwrap_or("bad arguments");
    let first = first.strip_prefix("error: ").unwrap_or(first);
    // clap quotes values in '…': shorten each quoted part.
    let shortened: Vec<String> = first
        .split('\'')
        .enumerate()
        .map(|(i, part)| {
            if i % 2 == 1 {
                short(part)
            } else {
                part.to_string()
            }
        })
        .collect();
    format!(
        "{}: error: {} (see `cargo {} --help`)",
        label(prog),
        shortened.join("'"),
        label(prog)
    )
}

/// `xtask PROG` (or `xtask` for the top level) as messages name the command.
fn label(prog: &str) -> String {
    if prog.is_empty() {
        "xtask".into()
    } else {
        format!("xtask {prog}")
    }
}

/// Prints an input error (one line, prefixed with the command) and returns [`EXIT_USAGE`].
pub fn bad_input(prog: &str, message: &str) -> i32 {
    let line = message.lines().next().unwrap_or(message);
    eprintln!("{}: error: {line}", label(prog));
    EXIT_USAGE
}

/// A clap value parser: a finite number (no NaN, no infinity).
pub fn finite(s: &str) -> Result<f64, String> {
    let v: f64 = s.parse().map_err(|_| "not a number".to_string())?;
    if v.is_finite() {
        Ok(v)
    } else {
        Err("not a finite number".into())
    }
}

/// A clap value parser: a finite number ≥ 0.
pub fn non_negative(s: &str) -> Result<f64, String> {
    let v = finite(s)?;
    if v >= 0.0 {
        Ok(v)
    } else {
        Err("must be ≥ 0".into())
    }
}

/// A clap value parser: the solver tolerance, in (1e-10, 1e-2).
pub fn tolerance(s: &str) -> Result<f64, String> {
    let v = finite(s)?;
    if v > 1e-10 && v < 1e-2 {
        Ok(v)
    } else {
        Err(format!("{} is outside (1e-10, 1e-2)", num(v)))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn values_are_cut_and_numbers_readable() {
        let long = "x".repeat(1000);
        let cut = short(&long);
        assert_eq!(cut.chars().count(), ECHO_CHARS + 1);
        assert!(cut.ends_with('…'));
        assert_eq!(short("abc"), "abc");
        assert_eq!(num(1e308), "1e308");
        assert_eq!(num(2.5), "2.5");
        assert_eq!(num(1e-9), "1e-9");
        assert!(finite("NaN").is_err() && finite("inf").is_err() && finite("abc").is_err());
        assert!(non_negative("-1").is_err());
        assert_eq!(tolerance("1e-6"), Ok(1e-6));
    }
}
