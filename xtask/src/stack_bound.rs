//! Static worst-case stack depth of a Thumb-2 image from its ELF (issue 15's budget is static
//! RAM + stack, and the part's image cannot boot under QEMU to measure it). A function's frame
//! is all it pushes or subtracts from SP; its calls are BL, branches out of it (tail calls, frame
//! still counted) and BLX/BX through a register it loads itself (MOVW/MOVT, a literal: dataflow
//! over its branches and IT blocks). A root's depth is its frame plus its deepest callee's; the
//! total stacks thread and handlers, one exception entry each. SP set from a register,
//! recursion or an unresolved indirect call withholds a bound. Panic paths format through
//! `&dyn Write` vtables: cut from the roots at `core::panicking::*`, reported apart.

use object::SectionKind::{Data, ReadOnlyData, Text};
use object::{Object, ObjectSection, ObjectSymbol, SymbolKind};
use std::borrow::Cow;
use std::collections::{BTreeMap, HashMap};
use std::fmt;

mod thumb;

use thumb::scan;

/// Where an image uses its stack: the reset handler (init and idle run above it), interrupt
/// handlers from lowest priority to highest (each may preempt those before it), the bytes one
/// exception entry stacks, and the fault handler (terminal, reported apart).
pub struct Contexts {
    pub thread: &'static str,
    /// The thread's init, if it runs with interrupts masked until it returns (RTIC's resource
    /// init: checked in the code, else ignored): handlers stack on its frame, not its callees'.
    pub masked_init: Option<&'static str>,
    pub handlers: &'static [&'static str],
    pub entry_bytes: u32,
    pub fault: &'static str,
}

/// The part's RTIC image: USART6 dispatches the priority-1 background task, TIM3 is the
/// priority-2 tick. An entry with the FPU on stacks 26 words (lazy stacking reserved), plus
/// 4 B of padding when SP was not 8-byte aligned.
pub const FLIGHT: Contexts = Contexts {
    thread: "Reset",
    masked_init: Some("::__rtic_init_resources"),
    handlers: &["USART6", "TIM3"],
    entry_bytes: 104 + 4,
    fault: "HardFault",
};

/// A function of the image: its calls resolved to function indices, what withholds its bound.
#[derive(Default)]
struct Func {
    name: String,
    frame: u32,
    callees: Vec<usize>,
    unresolved: Vec<String>,
    dynamic: bool,
    panic: bool,
    masked_calls: Vec<usize>,
    unmasks_last: bool,
}

/// One root's bound, or what withholds it (unresolved indirect calls, recursion, SP set from a
/// register); its deepest path (function, frame); the panic entries it calls, cut.
#[derive(Debug, Default)]
pub struct Depth {
    pub label: String,
    pub bytes: Option<u32>,
    pub unresolved: Vec<String>,
    pub recursive: Vec<String>,
    pub dynamic: Vec<String>,
    pub path: Vec<(String, u32)>,
    pub panics: Vec<String>,
}

/// The bound of an image. `panic`: the panic entries uncut, how deep a panic goes below its call.
#[derive(Debug)]
pub struct Report {
    pub thread: Depth,
    /// The thread once interrupts open: the masked init a leaf (its callees returned).
    pub after_init: Option<Depth>,
    /// From lowest priority to highest.
    pub handlers: Vec<Depth>,
    pub entry_bytes: u32,
    pub fault: Depth,
    pub panic: Depth,
}

impl Report {
    fn roots(&self) -> impl Iterator<Item = &Depth> {
        std::iter::once(&self.thread).chain(&self.handlers)
    }

    /// The thread once interrupts open (the whole thread unless init runs masked), then the
    /// handlers.
    fn open_roots(&self) -> impl Iterator<Item = &Depth> {
        let open = self.after_init.as_ref().unwrap_or(&self.thread);
        std::iter::once(open).chain(&self.handlers)
    }

    /// The thread with interrupts masked, or the thread once they open plus each handler and
    /// one exception entry per handler, whichever is deeper, if all are bounded.
    pub fn total(&self) -> Option<u32> {
        let entries = self.handlers.len() as u32 * self.entry_bytes;
        let sum: Option<u32> = self.open_roots().map(|d| d.bytes).sum();
        sum.zip(self.thread.bytes)
            .map(|(open, masked)| (open + entries).max(masked))
    }

    /// Unresolved indirect calls on the roots' graphs, panic paths cut.
    pub fn unresolved(&self) -> Vec<&str> {
        let mut all = Vec::new();
        for d in self.roots().chain([&self.fault]) {
            all.extend(d.unresolved.iter().map(String::as_str));
        }
        all.sort_unstable();
        all.dedup();
        all
    }
}

/// Bounds the part's image (`FLIGHT`).
pub fn bound(elf: &str) -> Result<Report, String> {
    bound_with(elf, &FLIGHT)
}

/// Bounds an image whose stack users are `ctx`.
pub fn bound_with(elf: &str, ctx: &Contexts) -> Result<Report, String> {
    let bytes = std::fs::read(elf).map_err(|e| format!("reading {elf}: {e}"))?;
    let file = object::File::parse(&*bytes).map_err(|e| format!("parsing {elf}: {e}"))?;
    let mut sections = Vec::new();
    for s in file.sections() {
        if matches!(s.kind(), Text | ReadOnlyData | Data) {
            sections.push((s.address() as u32, s.data().unwrap_or(&[])));
        }
    }
    let read = |a: u32, len: u32| {
        let (base, data) = sections
            .iter()
            .find(|(b, d)| a >= *b && a < b + d.len() as u32)?;
        data.get((a - base) as usize..(a - base + len) as usize)
    };
    let word = |a: u32| Some(u32::from_le_bytes(read(a, 4)?.try_into().ok()?));
    let (mut names, mut spans, mut marks) = (HashMap::new(), BTreeMap::new(), Vec::new());
    for sym in file.symbols() {
        let (Ok(name), a) = (sym.name(), sym.address() as u32) else {
            continue;
        };
        if name.starts_with('$') {
            marks.push((a, name.starts_with("$d"))); // ARM mapping symbols: $d data, $t code
        } else if sym.kind() == SymbolKind::Text {
            names.entry(name).or_insert(a & !1);
            if sym.size() > 0 {
                spans.entry(a & !1).or_insert((sym.size() as u32, name));
            }
        }
    }
    marks.sort_unstable();
    let starts: Vec<(u32, u32)> = spans.iter().map(|(&a, &(size, _))| (a, a + size)).collect();
    let index = |a: u32| starts.iter().position(|&(s, e)| (s..e).contains(&a));
    let mut funcs = Vec::new();
    for (&start, &(size, raw)) in &spans {
        let end = start + size;
        let mut data = Vec::new();
        for (n, &(a, is_data)) in marks.iter().enumerate() {
            if is_data && (start..end).contains(&a) {
                let code = marks[n + 1..].iter().find(|m| !m.1).map_or(end, |m| m.0);
                data.push((a, code.min(end)));
            }
        }
        let s = scan(read(start, size).unwrap_or(&[]), start, &data, &word);
        let name = addr2line::demangle_auto(Cow::from(raw), None).into_owned();
        let (frame, dynamic, panic) = (s.frame, s.dynamic, is_panic(&name));
        let mut f = Func {
            name,
            frame,
            dynamic,
            panic,
            masked_calls: s.masked_calls.iter().filter_map(|&t| index(t)).collect(),
            unmasks_last: s.unmasks_last,
            ..Func::default()
        };
        for t in s.calls {
            match index(t) {
                Some(c) => f.callees.push(c),
                None => f
                    .unresolved
                    .push(format!("{} calls {t:#x}, in no function", f.name)),
            }
        }
        for (pc, what, values) in s.indirect {
            let thumb = |a: u32| index(a).filter(|_| a & 1 == 1 && spans.contains_key(&(a - 1)));
            match values.and_then(|v| v.into_iter().map(thumb).collect::<Option<Vec<_>>>()) {
                Some(targets) => f.callees.extend(targets),
                None => f.unresolved.push(format!("{} at {pc:#x}: {what}", f.name)),
            }
        }
        funcs.push(f);
    }
    let root = |label: &str, funcs: &[Func]| {
        let mut d = Depth {
            label: label.to_string(),
            ..Depth::default()
        };
        let Some(mut at) = names.get(label).and_then(|&a| index(a)) else {
            d.unresolved.push(format!("no function `{label}`"));
            return d;
        };
        let mut marks = vec![Mark::New; funcs.len()];
        d.bytes = walk(funcs, at, true, &mut marks, &mut Vec::new(), &mut d);
        while let (Mark::Done(Some(_), next), true) = (marks[at], d.bytes.is_some()) {
            d.path.push((funcs[at].name.clone(), funcs[at].frame));
            let Some(next) = next else { break };
            at = next;
        }
        d.panics.sort_unstable();
        d.panics.dedup();
        d
    };
    let mut panic = Depth {
        label: "panic".into(),
        bytes: Some(0),
        ..Depth::default()
    };
    for f in (0..funcs.len()).filter(|&f| funcs[f].panic) {
        let marks = &mut vec![Mark::New; funcs.len()];
        let b = walk(&funcs, f, false, marks, &mut Vec::new(), &mut panic);
        panic.bytes = panic.bytes.zip(b).map(|(a, b)| a.max(b));
    }
    for list in [&mut panic.unresolved, &mut panic.recursive] {
        list.sort_unstable();
        list.dedup();
    }
    let (thread, fault) = (root(ctx.thread, &funcs), root(ctx.fault, &funcs));
    let handlers = ctx.handlers.iter().map(|h| root(h, &funcs)).collect();
    let after_init = ctx
        .masked_init
        .and_then(|suffix| funcs.iter().position(|f| f.name.ends_with(suffix)))
        .filter(|&i| runs_masked(&funcs, i))
        .map(|i| {
            let mut leaf = funcs;
            leaf[i].callees.clear();
            let mut d = root(ctx.thread, &leaf);
            d.label = format!("{} after {}", ctx.thread, leaf[i].name);
            d
        });
    let entry_bytes = ctx.entry_bytes;
    Ok(Report {
        thread,
        after_init,
        handlers,
        entry_bytes,
        fault,
        panic,
    })
}

/// Whether `init` runs with interrupts masked until it returns: every caller masks them in
/// straight-line code before the call, and each unmasking in `init` goes straight to its return.
fn runs_masked(funcs: &[Func], init: usize) -> bool {
    let mut callers = funcs
        .iter()
        .filter(|f| f.callees.contains(&init))
        .peekable();
    funcs[init].unmasks_last
        && callers.peek().is_some()
        && callers.all(|f| f.masked_calls.contains(&init))
}

/// The panic entry points: their paths format through vtables.
fn is_panic(name: &str) -> bool {
    name.starts_with("core::panicking::") || name.ends_with("rust_begin_unwind")
}

/// A function's state in a walk; when done, its depth and its deepest callee.
#[derive(Clone, Copy)]
enum Mark {
    New,
    Open,
    Done(Option<u32>, Option<usize>),
}

/// Depth of `f` (frame + deepest callee), panic entries cut when `cut`; what withholds it in `d`.
fn walk(
    funcs: &[Func],
    f: usize,
    cut: bool,
    marks: &mut [Mark],
    stack: &mut Vec<usize>,
    d: &mut Depth,
) -> Option<u32> {
    match marks[f] {
        Mark::Done(b, _) => return b,
        Mark::Open => {
            let from = stack.iter().position(|&s| s == f).unwrap_or(0);
            let cycle: Vec<&str> = stack[from..]
                .iter()
                .map(|&s| funcs[s].name.as_str())
                .collect();
            d.recursive
                .push(format!("{} → {}", cycle.join(" → "), funcs[f].name));
            return None;
        }
        Mark::New => {}
    }
    let func = &funcs[f];
    marks[f] = Mark::Open;
    stack.push(f);
    d.unresolved.extend(func.unresolved.iter().cloned());
    d.dynamic.extend(func.dynamic.then(|| func.name.clone()));
    let mut deepest = Some((0, None));
    for &c in &func.callees {
        if cut && funcs[c].panic {
            d.panics.push(funcs[c].name.clone());
            continue;
        }
        let b = walk(funcs, c, cut, marks, stack, d);
        deepest = deepest
            .zip(b)
            .map(|(x, b)| if b > x.0 { (b, Some(c)) } else { x });
    }
    stack.pop();
    let bounded = func.unresolved.is_empty() && !func.dynamic;
    let b = deepest.filter(|_| bounded).map(|(b, _)| b + func.frame);
    marks[f] = Mark::Done(b, deepest.and_then(|x| x.1));
    b
}

impl fmt::Display for Depth {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        if let Some(b) = self.bytes {
            return write!(f, "{} {b} B", self.label);
        }
        write!(f, "{}: no bound", self.label)?;
        let why = [&self.unresolved, &self.recursive, &self.dynamic];
        for (what, list) in ["unresolved", "recursive", "SP set from a register"]
            .iter()
            .zip(why)
        {
            if !list.is_empty() {
                write!(f, " ({what}: {})", list.join("; "))?;
            }
        }
        Ok(())
    }
}

impl fmt::Display for Report {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let roots: Vec<String> = self.open_roots().map(|d| d.to_string()).collect();
        let (roots, n, entry) = (roots.join(" + "), self.handlers.len(), self.entry_bytes);
        match self.total() {
            Some(t) => write!(f, "Stack bound {t} B = ")?,
            None => write!(f, "No stack bound: ")?,
        }
        if self.after_init.is_some() {
            write!(f, "the deeper of {} (interrupts masked) and ", self.thread)?;
        }
        write!(
            f,
            "{roots} + {n} exception entries of {entry} B; {}. ",
            self.fault
        )?;
        for (i, (name, b)) in self.thread.path.iter().enumerate() {
            let lead = if i == 0 {
                "Deepest thread path: "
            } else {
                " → "
            };
            write!(f, "{lead}{name} {b}")?;
        }
        for d in self.roots().filter(|d| !d.panics.is_empty()) {
            write!(
                f,
                ". {} calls panic entries (cut): {}",
                d.label,
                d.panics.join(", ")
            )?;
        }
        let (vt, cycles) = (self.panic.unresolved.len(), self.panic.recursive.len());
        match self.panic.bytes {
            Some(b) => write!(f, ". A panic adds ≤ {b} B")?,
            None => write!(
                f,
                ". A panic's depth: no bound ({vt} vtable calls, {cycles} cycles)"
            )?,
        }
        let n = self.unresolved().len();
        write!(f, ". Unresolved indirect calls outside panic paths: {n}.")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn depth_cuts_panics_and_withholds_recursion() {
        let f = |name: &str, frame, callees: Vec<usize>| {
            let (name, panic) = (name.to_string(), is_panic(name));
            Func {
                name,
                frame,
                callees,
                panic,
                ..Func::default()
            }
        };
        let funcs = [
            f("a", 8, vec![1, 2]),
            f("b", 16, vec![3]),
            f("core::panicking::panic", 100, vec![]),
            f("c", 4, vec![]),
            f("d", 4, vec![4]),
        ];
        let run = |root, cut| {
            let mut d = Depth::default();
            let b = walk(
                &funcs,
                root,
                cut,
                &mut [Mark::New; 5],
                &mut Vec::new(),
                &mut d,
            );
            (b, d)
        };
        let (b, d) = run(0, true);
        assert_eq!(
            (b, d.panics),
            (Some(28), vec!["core::panicking::panic".to_string()])
        );
        assert_eq!(run(0, false).0, Some(108));
        let (b, d) = run(4, true);
        assert_eq!((b, d.recursive), (None, vec!["d → d".to_string()]));
    }

    #[test]
    fn the_bound_is_the_deeper_phase_and_none_if_either_is_unbounded() {
        let d = |bytes| Depth {
            bytes,
            ..Depth::default()
        };
        let mut r = Report {
            thread: d(Some(1000)),
            after_init: Some(d(Some(200))),
            handlers: vec![d(Some(100)), d(Some(50))],
            entry_bytes: 10,
            fault: d(Some(8)),
            panic: d(None),
        };
        assert_eq!(r.total(), Some(1000), "init, masked, is deeper");
        r.thread.bytes = Some(300);
        assert_eq!(r.total(), Some(370), "idle + handlers + entries");
        r.after_init = None;
        assert_eq!(
            r.total(),
            Some(470),
            "unchecked init: the whole thread under the handlers"
        );
        r.thread.bytes = None;
        r.after_init = Some(d(Some(200)));
        assert_eq!(r.total(), None);
    }

    #[test]
    #[ignore = "reads the built images"]
    fn print_images() {
        let root = crate::shell::workspace_root();
        let flight = root.join("target/part/thumbv7em-none-eabihf/release/noback-stm32f405");
        println!("{}", bound(&flight.to_string_lossy()).unwrap());
        let m3 = Contexts {
            thread: "Reset",
            masked_init: None,
            handlers: &["PendSV", "SysTick"],
            entry_bytes: 32 + 4,
            fault: "HardFault",
        };
        let m3_elf = root.join("target/thumbv7m-none-eabi/release/noback-fw");
        println!("{}", bound_with(&m3_elf.to_string_lossy(), &m3).unwrap());
    }
}
