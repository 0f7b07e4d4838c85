//! The generator's building blocks: its PRNG (splitmix64), the names and elements it emits, and
//! their JSON text. Writing is direct to an `io::Write`, in the program format of docs/format.md;
//! nothing here decides the shape of a program (that is `super`).

use std::fmt;
use std::io::{self, Write};

// ---------------------------------------------------------------------------------------------
// PRNG

/// splitmix64 (Steele, Lea & Flood 2014), with `below` by the high half of a 64×64-bit product.
///
/// Hand-written on purpose: the exact sequence decides every generated program (`gen` output
/// is byte-identical for a seed, docs/gen.md), and no crate gives both this step and this
/// mapping to a range (`rand`'s ranges reject and redraw, so every program would change); the
/// step itself is five lines.
pub(super) struct Rng(pub(super) u64);

impl Rng {
    pub(super) fn new(seed: u64) -> Self {
        Rng(seed)
    }

    pub(super) fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }

    /// Uniform in `0..n` (`n > 0`).
    pub(super) fn below(&mut self, n: usize) -> usize {
        ((self.next_u64() as u128 * n as u128) >> 64) as usize
    }

    /// Uniform in `lo..=hi`.
    pub(super) fn range(&mut self, lo: usize, hi: usize) -> usize {
        lo + self.below(hi - lo + 1)
    }

    /// True with probability `1/n`.
    pub(super) fn one_in(&mut self, n: usize) -> bool {
        self.below(n) == 0
    }
}

// ---------------------------------------------------------------------------------------------
// Names, operands, elements

#[derive(Clone, Copy, PartialEq, Eq, Debug)]
pub(super) enum Name {
    I(usize),
    Q(usize),
    M(usize, usize),
    N(usize, usize),
    T(usize, usize),
    C(usize, usize),
    Idx(usize),
    Sr(usize),
    Sb(usize, usize),
    Sn(usize),
    /// The hot variable `FAULT` (`hot_fraction`).
    Hot,
}

impl fmt::Display for Name {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match *self {
            Name::I(i) => write!(f, "I{i}"),
            Name::Q(i) => write!(f, "Q{i}"),
            Name::M(j, p) => write!(f, "M{j}_{p}"),
            Name::N(j, p) => write!(f, "N{j}_{p}"),
            Name::T(j, p) => write!(f, "T{j}_{p}"),
            Name::C(j, p) => write!(f, "C{j}_{p}"),
            Name::Idx(k) => write!(f, "i{k}"),
            Name::Sr(k) => write!(f, "SR{k}"),
            Name::Sb(k, i) => write!(f, "S{k}_B{i}"),
            Name::Sn(k) => write!(f, "S{k}_N"),
            Name::Hot => f.write_str("FAULT"),
        }
    }
}

#[derive(Clone, Copy, Debug)]
pub(super) enum Opnd {
    Var(Name),
    Field(Name, &'static str),
    Int(i64),
}

impl fmt::Display for Opnd {
    /// As JSON.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match *self {
            Opnd::Var(n) => write!(f, "\"{n}\""),
            Opnd::Field(n, field) => write!(f, "\"{n}.{field}\""),
            Opnd::Int(i) => write!(f, "{i}"),
        }
    }
}

#[derive(Clone, Copy, PartialEq, Eq, Debug)]
pub(super) enum Timer {
    Ton,
    Tof,
    Tp,
}

impl Timer {
    pub(super) fn of(j: usize, p: usize) -> Timer {
        match (5 * j + 3 * p) % 8 {
            0 => Timer::Tof,
            1 => Timer::Tp,
            _ => Timer::Ton,
        }
    }
    pub(super) fn key(self) -> &'static str {
        match self {
            Timer::Ton => "ton",
            Timer::Tof => "tof",
            Timer::Tp => "tp",
        }
    }
    pub(super) fn type_name(self) -> &'static str {
        match self {
            Timer::Ton => "TON",
            Timer::Tof => "TOF",
            Timer::Tp => "TP",
        }
    }
    pub(super) fn pt(self) -> &'static str {
        match self {
            Timer::Ton => "T#100ms",
            Timer::Tof => "T#250ms",
            Timer::Tp => "T#1s",
        }
    }
}

pub(super) fn counter_is_ctu(j: usize, p: usize) -> bool {
    (j + p).is_multiple_of(2)
}

#[derive(Clone, Debug)]
pub(super) enum Elem {
    Contact {
        var: Opnd,
        negated: bool,
        edge: Option<&'static str>,
    },
    Compare {
        op: &'static str,
        a: Opnd,
        b: Opnd,
    },
    Or(Vec<Vec<Elem>>),
    Coil {
        var: Name,
        negated: bool,
    },
    Set(Name),
    Reset(Name),
    Branch(Vec<Vec<Elem>>),
    Timer {
        kind: Timer,
        var: Name,
    },
    Ctu {
        var: Name,
        pv: Opnd,
        reset: Opnd,
    },
    Ctd {
        var: Name,
        pv: Opnd,
        load: Opnd,
    },
    Move {
        from: Opnd,
        to: Name,
    },
    Op {
        op: &'static str,
        a: Opnd,
        b: Opnd,
        out: Name,
    },
    Jmp(usize),
    Ret,
    End,
    Call(usize),
    For {
        k: usize,
    },
    Next,
}

pub(super) fn contact(n: Name, negated: bool) -> Elem {
    Elem::Contact {
        var: Opnd::Var(n),
        negated,
        edge: None,
    }
}

pub(super) fn write_series<W: Write>(w: &mut W, series: &[Elem]) -> io::Result<()> {
    w.write_all(b"[")?;
    for (i, e) in series.iter().enumerate() {
        if i > 0 {
            w.write_all(b",")?;
        }
        write_elem(w, e)?;
    }
    w.write_all(b"]")
}

pub(super) fn write_branches<W: Write>(
    w: &mut W,
    key: &str,
    branches: &[Vec<Elem>],
) -> io::Result<()> {
    write!(w, "{{\"{key}\":[")?;
    for (i, s) in branches.iter().enumerate() {
        if i > 0 {
            w.write_all(b",")?;
        }
        write_series(w, s)?;
    }
    w.write_all(b"]}")
}

pub(super) fn write_elem<W: Write>(w: &mut W, e: &Elem) -> io::Result<()> {
    match e {
        Elem::Contact { var, negated, edge } => {
            write!(w, "{{\"contact\":{var}")?;
            if *negated {
                w.write_all(b",\"negated\":true")?;
            }
            if let Some(edge) = edge {
                write!(w, ",\"edge\":\"{edge}\"")?;
            }
            w.write_all(b"}")
        }
        Elem::Compare { op, a, b } => write!(w, "{{\"compare\":\"{op}\",\"a\":{a},\"b\":{b}}}"),
        Elem::Or(b) => write_branches(w, "or", b),
        Elem::Coil {
            var,
            negated: false,
        } => write!(w, "{{\"coil\":\"{var}\"}}"),
        Elem::Coil { var, negated: true } => write!(w, "{{\"coil\":\"{var}\",\"negated\":true}}"),
        Elem::Set(v) => write!(w, "{{\"set\":\"{v}\"}}"),
        Elem::Reset(v) => write!(w, "{{\"reset\":\"{v}\"}}"),
        Elem::Branch(b) => write_branches(w, "branch", b),
        Elem::Timer { kind, var } => write!(
            w,
            "{{\"{}\":\"{var}\",\"pt\":\"{}\"}}",
            kind.key(),
            kind.pt()
        ),
        Elem::Ctu { var, pv, reset } => {
            write!(w, "{{\"ctu\":\"{var}\",\"pv\":{pv},\"reset\":{reset}}}")
        }
        Elem::Ctd { var, pv, load } => {
            write!(w, "{{\"ctd\":\"{var}\",\"pv\":{pv},\"load\":{load}}}")
        }
        Elem::Move { from, to } => write!(w, "{{\"move\":{from},\"to\":\"{to}\"}}"),
        Elem::Op { op, a, b, out } => {
            write!(w, "{{\"op\":\"{op}\",\"in\":[{a},{b}],\"out\":\"{out}\"}}")
        }
        Elem::Jmp(l) => write!(w, "{{\"jmp\":\"L{l}\"}}"),
        Elem::Ret => w.write_all(b"{\"ret\":true}"),
        Elem::End => w.write_all(b"{\"end\":true}"),
        Elem::Call(k) => write!(w, "{{\"call\":\"SBR_{k}\"}}"),
        Elem::For { k } => write!(w, "{{\"for\":{{\"var\":\"i{k}\",\"from\":1,\"to\":3}}}}"),
        Elem::Next => w.write_all(b"{\"next\":true}"),
    }
}
