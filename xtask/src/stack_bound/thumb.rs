//! The Thumb/Thumb-2 side of the stack bound: decodes the instructions it follows and reduces
//! a function's code to its frame, its call targets and its indirect sites (register dataflow).

use std::collections::HashMap;

/// A register holds one of these values (`None`: unknown); past this many, unknown.
const MAX_VALUES: usize = 8;

/// What one instruction does that the bound follows.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Op {
    /// Pushes or subtracts this many bytes.
    Alloc(u32),
    /// BL to this address.
    Call(u32),
    /// B, B<c>, B.W, CBZ to this address; true when it may fall through.
    Branch(u32, bool),
    /// BLX (true), BX or MOV PC (false) through this register.
    Indirect(usize, bool),
    /// Ends the path: a return or a table branch.
    Stop,
    /// PC loaded from memory (not a return) or computed: unresolvable.
    PcLoad,
    /// SP written other than as below: a dynamic allocation.
    SpDynamic,
    /// SP set from this register: an epilogue if it is a frame pointer.
    SpFrom(usize),
    /// The register is set from SP (a frame pointer).
    FromSp(usize),
    /// The register is set to this value (MOVW, MOV #imm, ADR).
    Const(usize, u32),
    Movt(usize, u16),
    Mov(usize, usize),
    /// `ADD Rd, Rn, Rm, LSL #k`: a jump-table index when Rn holds an ADR address.
    AddIndex(usize, usize),
    /// LDR of the word at this address.
    Literal(usize, u32),
    /// IT: this many instructions follow conditionally.
    It(u8),
    /// Writes these registers (a mask), nothing else followed.
    Writes(u16),
    /// CPSIE i (true) or CPSID i (false): interrupts unmasked or masked.
    Mask(bool),
}

fn sext(v: u32, bits: u32) -> u32 {
    (((v << (32 - bits)) as i32) >> (32 - bits)) as u32
}

/// ThumbExpandImm (ARMv7-M ARM A5.3.2).
fn expand(imm12: u32) -> u32 {
    let b = imm12 & 0xFF;
    match (imm12 >> 10, (imm12 >> 8) & 3) {
        (0, 0) => b,
        (0, 1) => b << 16 | b,
        (0, 2) => b << 24 | b << 8,
        (0, _) => b * 0x0101_0101,
        _ => (0x80 | imm12 & 0x7F).rotate_right(imm12 >> 7),
    }
}

fn when(c: bool, mask: u16) -> u16 {
    if c {
        mask
    } else {
        0
    }
}

/// Whether the halfword starts a 32-bit instruction.
fn is_wide(h: u16) -> bool {
    h >> 11 >= 0b11101
}

/// Decodes the instruction at `pc` (`l`: the second halfword of a 32-bit one).
fn decode(h: u16, l: u16, pc: u32) -> Op {
    let op = if is_wide(h) {
        wide(h, l, pc)
    } else {
        narrow(h, pc)
    };
    match op {
        Op::Writes(m) if m & 1 << 13 != 0 => Op::SpDynamic,
        Op::Writes(m) if m & 1 << 15 != 0 => Op::PcLoad,
        op => op,
    }
}

fn narrow(h: u16, pc: u32) -> Op {
    let (lo, hi, imm8) = ((h & 7) as usize, (h >> 8 & 7) as usize, u32::from(h & 0xFF));
    let (d, m) = ((h >> 4 & 8 | h & 7) as usize, (h >> 3 & 0xF) as usize);
    let pc4 = pc + 4;
    let cb = u32::from(h >> 9 & 1) << 6 | u32::from(h >> 3 & 0x1F) << 1;
    match h {
        _ if h & 0xFE00 == 0xB400 => Op::Alloc(4 * (h & 0x1FF).count_ones()), // PUSH
        _ if h & 0xFF00 == 0xBD00 => Op::Stop,                                // POP {.., PC}
        _ if h & 0xFF00 == 0xBC00 => Op::Writes(h & 0xFF),
        _ if h & 0xFF80 == 0xB080 => Op::Alloc(4 * u32::from(h & 0x7F)), // SUB SP, #imm
        _ if h & 0xFF00 == 0xBF00 && h & 0xF != 0 => Op::It(4 - (h & 0xF).trailing_zeros() as u8),
        _ if h & 0xF500 == 0xB100 => Op::Branch(pc4 + cb, true), // CBZ, CBNZ
        _ if h & 0xFFEA == 0xB662 => Op::Mask(h & 0x10 == 0),    // CPSIE i / CPSID i
        _ if h & 0xFF00 == 0xB200 || h & 0xFF00 == 0xBA00 => Op::Writes(1 << lo),
        _ if h & 0xF000 == 0xB000 => Op::Writes(0),
        _ if h & 0xFF80 == 0x4700 && m == 14 => Op::Stop,
        _ if h & 0xFF00 == 0x4700 => Op::Indirect(m, h & 0x80 != 0),
        _ if h & 0xFF00 == 0x4600 => match (d, m) {
            (13, _) => Op::SpFrom(m),
            (15, _) => Op::Indirect(m, false),
            (_, 13) => Op::FromSp(d),
            _ => Op::Mov(d, m),
        },
        _ if h & 0xFF00 == 0x4500 => Op::Writes(0),
        _ if h & 0xFF00 == 0x4400 => Op::Writes(1 << d),
        _ if h & 0xF800 == 0x4800 => Op::Literal(hi, (pc4 & !3) + 4 * imm8),
        _ if h & 0xF800 == 0xA800 => Op::FromSp(hi),
        _ if h & 0xF800 == 0xA000 => Op::Const(hi, (pc4 & !3) + 4 * imm8), // ADR
        _ if h & 0xF800 == 0x2000 => Op::Const(hi, imm8),
        _ if h & 0xF800 == 0xC800 => Op::Writes(h & 0xFF | 1 << hi), // LDM
        _ if h & 0xF000 == 0xD000 && h >> 9 & 7 == 7 => Op::Writes(0), // UDF, SVC
        _ if h & 0xF000 == 0xD000 => Op::Branch(pc4.wrapping_add(sext(imm8 << 1, 9)), true),
        _ if h & 0xF800 == 0xE000 => {
            Op::Branch(pc4.wrapping_add(sext(u32::from(h & 0x7FF) << 1, 12)), false)
        }
        _ if h & 0xE000 == 0x2000 || h >> 12 == 9 || h >> 12 == 0xC => Op::Writes(1 << hi),
        _ => Op::Writes(1 << lo),
    }
}

fn wide(h: u16, l: u16, pc: u32) -> Op {
    let [rn, rd, rt] = [h & 0xF, l >> 8 & 0xF, l >> 12].map(usize::from);
    let (pc4, load, wb) = (pc + 4, h & 0x10 != 0, 1u16 << rn);
    if h & 0xF800 == 0xF000 && l & 0x8000 != 0 {
        // branches and miscellaneous control
        let [s, j1, j2] = [h >> 10 & 1, l >> 13 & 1, l >> 11 & 1].map(u32::from);
        let low = u32::from(h & 0x3FF) << 12 | u32::from(l & 0x7FF) << 1;
        let (i1, i2) = (!(j1 ^ s) & 1, !(j2 ^ s) & 1);
        let far = pc4.wrapping_add(sext(s << 24 | i1 << 23 | i2 << 22 | low, 25));
        let near = pc4.wrapping_add(sext(s << 20 | j2 << 19 | j1 << 18 | (low & 0x3_FFFF), 21));
        return match l & 0xD000 {
            0xD000 => Op::Call(far),
            0x9000 => Op::Branch(far, false),
            0x8000 if h >> 7 & 7 != 7 => Op::Branch(near, true),
            0xC000 => Op::PcLoad, // BLX to ARM state: not on M profile
            _ => Op::Writes(when(h & 0xFFE0 == 0xF3E0, 1 << rd)), // MRS
        };
    }
    if h & 0xF800 == 0xF000 {
        // data processing, immediate
        let [i, imm3, imm8] = [h >> 10 & 1, l >> 12 & 7, l & 0xFF].map(u32::from);
        let imm12 = i << 11 | imm3 << 8 | imm8;
        let plain = h & 0x200 != 0;
        let add = h & 0xFBF0 == 0xF200 || h & 0xFBE0 == 0xF100;
        let sub = h & 0xFBF0 == 0xF2A0 || h & 0xFBE0 == 0xF1A0;
        return match (rd, rn) {
            _ if h & 0xFBF0 == 0xF240 => Op::Const(rd, u32::from(h & 0xF) << 12 | imm12),
            _ if h & 0xFBEF == 0xF04F => Op::Const(rd, expand(imm12)),
            _ if h & 0xFBF0 == 0xF2C0 => Op::Movt(rd, (h & 0xF) << 12 | imm12 as u16),
            (15, _) if !plain => Op::Writes(0), // TST, TEQ, CMP, CMN
            (13, 13) if sub => Op::Alloc(if plain { imm12 } else { expand(imm12) }),
            (13, 13) if add => Op::Writes(0),
            (13, _) if add || sub => Op::SpFrom(rn),
            (_, 13) if add || sub => Op::FromSp(rd),
            (_, 15) if add => Op::Const(rd, (pc4 & !3) + imm12), // ADR
            (_, 15) if sub => Op::Const(rd, (pc4 & !3) - imm12),
            _ => Op::Writes(1 << rd),
        };
    }
    if h & 0xFE40 == 0xE800 {
        // LDM, STM
        return match h {
            0xE92D => Op::Alloc(4 * l.count_ones()),
            0xE8BD if l & 0x8000 != 0 => Op::Stop,
            0xE8BD => Op::Writes(l),
            _ => Op::Writes(when(load, l) | when(h & 0x20 != 0, wb)),
        };
    }
    if h & 0xFE40 == 0xE840 {
        // load/store dual or exclusive, table branch
        let wb = when(h & 0x20 != 0 && !(load && rn == 13 && h & 0x80 != 0), wb);
        let status = (1 << rd | 1 << (l & 0xF)) & 0x5FFF; // STREX's result register
        return match h {
            _ if h & 0xFFF0 == 0xE8D0 && l & 0xFFE0 == 0xF000 => Op::Stop,
            0xE96D => Op::Alloc(4 * u32::from(l & 0xFF)),
            _ if load => Op::Writes(1 << rt | when(rd != 15, 1 << rd) | wb),
            _ => Op::Writes(status | wb),
        };
    }
    if h & 0xFE00 == 0xEA00 {
        // data processing, shifted register
        let rm = (l & 0xF) as usize;
        return match (rd, rm) {
            (15, _) => Op::Writes(0),
            _ if h & 0xFFF0 == 0xEB00 && rd != 13 && rn < 13 => Op::AddIndex(rd, rn),
            _ if h & 0xFFEF != 0xEA4F || l & 0x70F0 != 0 => Op::Writes(1 << rd),
            (13, _) => Op::SpFrom(rm),
            (_, 13) => Op::FromSp(rd),
            _ => Op::Mov(rd, rm),
        };
    }
    if h & 0xFE00 == 0xF800 {
        // load/store single
        let back = h & 0x80 == 0 && l & 0x900 == 0x900;
        let imm = u32::from(l & 0xFFF);
        let lit = (pc4 & !3).wrapping_add(if h & 0x80 != 0 {
            imm
        } else {
            imm.wrapping_neg()
        });
        return match () {
            _ if h == 0xF84D && l & 0xF00 == 0xD00 => Op::Alloc(u32::from(l & 0xFF)),
            _ if h & 0xFF7F == 0xF85F && rt != 15 => Op::Literal(rt, lit),
            _ if load && rt == 15 && h & 0x60 != 0x40 => Op::Writes(0), // PLD, PLI
            _ if load && rt == 15 && rn == 13 && back => Op::Stop,
            _ if load && rt == 15 => Op::PcLoad,
            _ if load && rn == 13 && (!back || l & 0x200 != 0) => Op::Writes(1 << rt), // a pop
            _ => Op::Writes(when(load, 1 << rt) | when(back, wb)),
        };
    }
    if h & 0xFE00 == 0xFA00 {
        // data processing (register), multiply, divide
        return Op::Writes(1 << rd | when(h & 0xFF80 == 0xFB80 && rt != 15, 1 << rt));
    }
    let sp_back = when(h & 0xEE20 == 0xEC20 && rn == 13, wb); // VLDM, VSTM SP!
    match h & 0xFFBF {
        0xED2D => Op::Alloc(4 * u32::from(l & 0xFF)), // VPUSH
        0xECBD => Op::Writes(0),                      // VPOP
        _ => Op::Writes((1 << rt | wb) & 0x5FFF | sp_back), // VMOV, VMRS to core; VLDM Rn!
    }
}

/// One decoded instruction: its address, what it does, whether an IT block makes it conditional.
struct Insn {
    pc: u32,
    op: Op,
    cond: bool,
}

type Regs = [Option<Vec<u32>>; 16];
pub(super) type Word<'a> = &'a dyn Fn(u32) -> Option<u32>;

/// One function's code, reduced: its frame, call targets, indirect sites (address, text, the
/// values the register may hold), and whether it sets SP dynamically.
#[derive(Default)]
pub(super) struct Scan {
    pub(super) frame: u32,
    pub(super) calls: Vec<u32>,
    pub(super) indirect: Vec<(u32, String, Option<Vec<u32>>)>,
    pub(super) dynamic: bool,
    /// Targets of calls made in straight-line code after a CPSID i (interrupts masked).
    pub(super) masked_calls: Vec<u32>,
    /// Has a CPSIE i, and each goes straight to a return: no call after interrupts open.
    pub(super) unmasks_last: bool,
}

/// Decodes the function at `start` (`data`: literal-pool ranges to skip; `word`: reads flash).
pub(super) fn scan(code: &[u8], start: u32, data: &[(u32, u32)], word: Word) -> Scan {
    let half = |at: usize| Some(u16::from_le_bytes(code.get(at..at + 2)?.try_into().ok()?));
    let (mut insns, mut at, mut it) = (Vec::new(), 0, 0);
    while let Some(h) = half(at) {
        let pc = start + at as u32;
        if let Some(&(_, end)) = data.iter().find(|(s, e)| (*s..*e).contains(&pc)) {
            at = (end - start) as usize;
            continue;
        }
        let op = decode(h, half(at + 2).unwrap_or(0), pc);
        insns.push(Insn {
            pc,
            op,
            cond: it > 0,
        });
        it = if let Op::It(n) = op { n } else { it.max(1) - 1 };
        at += if is_wide(h) { 4 } else { 2 };
    }
    let (end, mut s) = (start + code.len() as u32, Scan::default());
    let fp = insns.iter().fold(0u16, |m, i| match i.op {
        Op::FromSp(r) => m | 1 << r,
        _ => m,
    });
    let has_indirect = insns.iter().any(|i| matches!(i.op, Op::Indirect(..)));
    let flow = if has_indirect {
        flow(&insns, word)
    } else {
        Vec::new()
    };
    for (n, i) in insns.iter().enumerate() {
        match i.op {
            Op::Alloc(b) => s.frame += b,
            Op::Call(t) => s.calls.push(t),
            Op::Branch(t, _) if !(start..end).contains(&t) => s.calls.push(t),
            Op::SpDynamic => s.dynamic = true,
            Op::SpFrom(r) => s.dynamic |= fp & 1 << r == 0,
            Op::PcLoad => s.indirect.push((i.pc, "PC loaded".into(), None)),
            Op::Indirect(r, link) => {
                let values = flow.get(n).and_then(|f| f.as_ref()?[r].clone());
                let here = |a: &u32| a & 1 == 0 && (start..end).contains(a);
                if link || !values.as_ref().is_some_and(|v| v.iter().all(here)) {
                    let what = format!("{} r{r}", if link { "blx" } else { "bx" });
                    s.indirect.push((i.pc, what, values)); // else a jump table in the function
                }
            }
            _ => {}
        }
    }
    (s.masked_calls, s.unmasks_last) = masking(&insns);
    s
}

/// The calls made with interrupts masked (straight line from a CPSID i), and whether every
/// CPSIE i runs straight to a return.
fn masking(insns: &[Insn]) -> (Vec<u32>, bool) {
    let (mut calls, mut masked, mut unmasks, mut in_tail) = (Vec::new(), false, 0, false);
    for i in insns {
        // Neither transfers control nor changes the mask (conditional or not).
        let inert = matches!(
            i.op,
            Op::Alloc(_) | Op::Writes(_) | Op::Const(..) | Op::Movt(..) | Op::Mov(..)
        ) || matches!(i.op, Op::Literal(..) | Op::FromSp(_) | Op::AddIndex(..));
        if in_tail {
            match i.op {
                Op::Stop if !i.cond => in_tail = false,
                _ if inert => {}
                _ => return (calls, false),
            }
            continue;
        }
        match i.op {
            Op::Mask(false) if !i.cond => masked = true,
            Op::Mask(true) => (masked, in_tail, unmasks) = (false, true, unmasks + 1),
            Op::Call(t) if masked && !i.cond => {
                calls.push(t);
                masked = false;
            }
            _ if inert => {}
            _ => masked = false,
        }
    }
    (calls, unmasks > 0 && !in_tail)
}

/// The values each register may hold before each instruction (MOVW/MOVT, MOV, literals).
fn flow(insns: &[Insn], word: Word) -> Vec<Option<Regs>> {
    let index: HashMap<u32, usize> = insns.iter().enumerate().map(|(n, i)| (i.pc, n)).collect();
    let succs = |n: usize| {
        let i = &insns[n];
        let ends = matches!(i.op, Op::Stop | Op::PcLoad | Op::Indirect(_, false));
        let mut next = Vec::new();
        if i.cond || !(ends || matches!(i.op, Op::Branch(_, false))) {
            next.extend((n + 1 < insns.len()).then_some(n + 1));
        }
        if let Op::Branch(t, _) = i.op {
            next.extend(index.get(&t));
        }
        next
    };
    // The entry, and blocks only a table branch reaches, start knowing nothing.
    let mut reached = vec![false; insns.len()];
    (0..insns.len())
        .flat_map(succs)
        .for_each(|k| reached[k] = true);
    let mut state: Vec<Option<Regs>> = vec![None; insns.len()];
    let mut work = Vec::new();
    for n in (0..insns.len()).filter(|&n| n == 0 || !reached[n]) {
        state[n] = Some(Default::default());
        work.push(n);
    }
    while let Some(n) = work.pop() {
        let Some(regs) = state[n].clone() else {
            continue;
        };
        let out = step(&insns[n], &regs, word);
        for k in succs(n) {
            let merged = state[k].as_ref().map_or(out.clone(), |old| meet(old, &out));
            if state[k].as_ref() != Some(&merged) {
                state[k] = Some(merged);
                work.push(k);
            }
        }
    }
    state
}

fn step(i: &Insn, regs: &Regs, word: Word) -> Regs {
    let mut out = regs.clone();
    let even = |v: &Vec<u32>| v.iter().all(|a| a & 1 == 0); // code addresses, not pointers
    let high = |v: u16| move |w: &u32| w & 0xFFFF | u32::from(v) << 16;
    match i.op {
        Op::Const(d, v) => out[d] = Some(vec![v]),
        Op::Movt(d, v) => out[d] = regs[d].clone().map(|s| s.iter().map(high(v)).collect()),
        Op::Mov(d, m) => out[d] = regs[m].clone(),
        Op::AddIndex(d, n) => out[d] = regs[n].clone().filter(even),
        Op::Literal(d, a) => out[d] = word(a).map(|w| vec![w]),
        Op::FromSp(d) => out[d] = None,
        _ => {}
    }
    let lost = match i.op {
        Op::Writes(m) => m,
        Op::Call(_) | Op::Indirect(_, true) => 0x500F, // AAPCS: r0-r3, r12, lr
        _ => 0,
    };
    (0..16)
        .filter(|r| lost >> r & 1 != 0)
        .for_each(|r| out[r] = None);
    if i.cond {
        meet(regs, &out)
    } else {
        out
    }
}

fn meet(a: &Regs, b: &Regs) -> Regs {
    std::array::from_fn(|r| {
        let (a, b) = (a[r].as_ref()?, b[r].as_ref()?);
        let mut u: Vec<u32> = a.iter().chain(b).copied().collect();
        u.sort_unstable();
        u.dedup();
        (u.len() <= MAX_VALUES).then_some(u)
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use Op::*;

    fn bytes(halves: &[u16]) -> Vec<u8> {
        halves.iter().flat_map(|h| h.to_le_bytes()).collect()
    }

    #[test]
    fn instructions_are_decoded() {
        let cases = [
            (0xB5F0, 0, Alloc(20)),             // push {r4-r7, lr}
            (0xB091, 0, Alloc(68)),             // sub sp, #68
            (0xE92D, 0x0F00, Alloc(16)),        // push.w {r8-r11}
            (0xF84D, 0xBD04, Alloc(4)),         // str r11, [sp, #-4]!
            (0xE96D, 0x4502, Alloc(8)),         // strd r4, r5, [sp, #-8]!
            (0xED2D, 0x8B04, Alloc(16)),        // vpush {d8, d9}
            (0xF5AD, 0x6D80, Alloc(1024)),      // sub.w sp, sp, #1024
            (0xF6AD, 0x1DEC, Alloc(2540)),      // subw sp, sp, #2540
            (0xB007, 0, Writes(0)),             // add sp, #28: a release
            (0x46BD, 0, SpFrom(7)),             // mov sp, r7
            (0xEBAD, 0x0D00, SpDynamic),        // sub.w sp, sp, r0
            (0x4485, 0, SpDynamic),             // add sp, r0
            (0x47C0, 0, Indirect(8, true)),     // blx r8
            (0x4770, 0, Stop),                  // bx lr
            (0xBDF0, 0, Stop),                  // pop {r4-r7, pc}
            (0xF85D, 0xFB04, Stop),             // ldr pc, [sp], #4
            (0xE8DF, 0xF006, Stop),             // tbb [pc, r6]
            (0xF241, 0x2634, Const(6, 0x1234)), // movw r6, #0x1234
            (0xF6C0, 0x0600, Movt(6, 0x0800)),  // movt r6, #0x0800
        ];
        for (h, l, op) in cases {
            assert_eq!(decode(h, l, 0x1000), op, "{h:#06x} {l:#06x}");
        }
        // From the part's image: main's `bl` to init, `beq.w` and `b.w` back, a `cbz`.
        let cases = [
            (0xF7FF, 0xFB5D, 0x0800_2F5A, Call(0x0800_2618)),
            (0xF43F, 0xAF35, 0x0800_1D32, Branch(0x0800_1BA0, true)),
            (0xF7FF, 0xBB08, 0x0800_1AC6, Branch(0x0800_10DA, false)),
            (0xB158, 0, 0x0800_028C, Branch(0x0800_02A6, true)),
            (0xE7FD, 0, 0x1012, Branch(0x1010, false)), // b.n .-2
            (0xF85F, 0x3008, 0x1002, Literal(3, 0x1004 - 8)), // ldr.w r3, [pc, #-8]
        ];
        for (h, l, pc, op) in cases {
            assert_eq!(decode(h, l, pc), op, "{h:#06x} {l:#06x} at {pc:#x}");
        }
    }

    #[test]
    fn register_calls_resolve_through_branches_and_it_blocks() {
        let code = bytes(&[
            0xB580, // push {r7, lr}
            0xF242, 0x0601, // movw r6, #0x2001
            0xF243, 0x0101, // movw r1, #0x3001
            0xBF08, 0x460E, // it eq; moveq r6, r1
            0x47B0, // 0x100E: blx r6
            0x2800, 0xD0FC, // cmp r0, #0; beq 0x100E
            0x6803, 0x4798, // ldr r3, [r0]; blx r3: from memory
            0x4B01, 0x4798, // ldr r3, [pc, #4]; blx r3: a literal
            0xBD80, 0xBF00, // pop {r7, pc}; nop
            0xB5F0, 0xB5F0, // $d at 0x1020: a pool that would decode as two pushes
        ]);
        let word = |a: u32| (a == 0x1020).then_some(0x4001);
        let s = scan(&code, 0x1000, &[(0x1020, 0x1024)], &word);
        assert_eq!((s.frame, s.dynamic), (8, false));
        let sites: Vec<_> = s
            .indirect
            .iter()
            .map(|(pc, _, v)| (*pc, v.clone()))
            .collect();
        let both = Some(vec![0x2001, 0x3001]);
        assert_eq!(
            sites,
            [(0x100E, both), (0x1016, None), (0x101A, Some(vec![0x4001]))]
        );
        // A frame pointer restored is an epilogue; SP set from another register is not.
        let epilogue = bytes(&[0xB580, 0x466F, 0xB082, 0x46BD, 0xBD80]);
        assert!(!scan(&epilogue, 0, &[], &|_| None).dynamic);
        assert!(scan(&bytes(&[0xB580, 0x4685, 0xBD80]), 0, &[], &|_| None).dynamic);
    }

    #[test]
    fn calls_with_interrupts_masked_and_an_unmasking_tail_are_found() {
        // push; cpsid i; bl (masked); cpsie i; bl (open); pop {pc}
        let main = bytes(&[
            0xB580, 0xB672, 0xF7FF, 0xFB5D, 0xB662, 0xF7FF, 0xFB5D, 0xBD80,
        ]);
        let s = scan(&main, 0x0800_2F56, &[], &|_| None);
        assert_eq!(s.masked_calls, [0x0800_2618]);
        assert!(!s.unmasks_last, "a call after cpsie i");
        // strb; cpsie i; add sp, #28; pop {r7, pc}: the unmasking runs straight to the return.
        let init = bytes(&[0xB580, 0x7001, 0xB662, 0xB007, 0xBD80]);
        let s = scan(&init, 0x1000, &[], &|_| None);
        assert!(s.masked_calls.is_empty() && s.unmasks_last);
        // A branch back after the unmasking may reach calls with interrupts open.
        let back = bytes(&[0xB580, 0x2800, 0xB662, 0xD0FC, 0xBD80]);
        assert!(!scan(&back, 0x1000, &[], &|_| None).unmasks_last);
        assert!(!scan(&bytes(&[0xB580, 0xBD80]), 0, &[], &|_| None).unmasks_last);
    }
}
