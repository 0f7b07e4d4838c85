//! Drawing one rung as a ladder diagram in inline SVG (IEC 61131-3 LD graphics, §4.2): left and
//! right power rails, contacts `| |` `|/|` `|P|` `|N|`, coils `( )` `(/)` `(S)` `(R)`, boxes
//! for comparisons, timers, counters, MOVE, arithmetic, calls and FOR, jumps and returns as
//! coil-like symbols; series left to right, parallel (`or`) and output (`branch`) branches
//! stacked with vertical joins. An FBD block (a rung the FBD lowering made from one block) is
//! drawn as the block: its box with input pins on the left (each with what feeds it: a
//! variable, a constant or an arc `#3.OUT` from another block) and output pins on the right with
//! the variables they write (IEC 61131-3 FBD, §4.3).
//!
//! Invariants: sizing ([`rung_size`], [`block_size`]) and drawing use the same measures, so a
//! drawing never leaves the box its size announces; text widths are estimated from a monospace
//! font (no browser measures anything). Coordinates are written with at most one decimal.
//!
//! Deliberately not here: where a card goes (`levels`), and editing or simulating the rung.

use super::esc;
use plc_fbd::{Block, Input, Network};
use plc_model::*;
use std::io::{self, Write};

/// Height of one row of elements.
const ROW: f64 = 40.0;
/// The wire's height inside a row.
const WIRE: f64 = 22.0;
/// Width of one character of the drawing's monospace font (10 px).
pub(super) const CHAR: f64 = 6.1;
/// Width of a power rail's margin.
const RAIL: f64 = 6.0;

/// Width and height of a drawing.
#[derive(Copy, Clone, Debug, PartialEq)]
pub(super) struct Size {
    pub w: f64,
    pub h: f64,
}

pub(super) fn text_w(s: &str) -> f64 {
    s.chars().count() as f64 * CHAR
}

fn operand(p: &Program, o: &Operand) -> String {
    match o {
        Operand::Var(r) => p.var_ref_name(*r),
        Operand::Const(v) => v.to_string(),
    }
}

/// What an element draws as: a contact or coil with its mark and name, or a box of text lines.
enum Shape {
    Contact { mark: &'static str, name: String },
    Coil { mark: &'static str, name: String },
    Box { lines: Vec<String> },
    Parallel,
}

fn shape(p: &Program, e: &Element) -> Shape {
    let var = |v: &VarId| p.var(*v).name.clone();
    let boxed = |lines: Vec<String>| Shape::Box { lines };
    match e {
        Element::Contact { var: r, kind } => Shape::Contact {
            mark: match kind {
                ContactKind::Normal => "",
                ContactKind::Negated => "/",
                ContactKind::Rising { .. } => "P",
                ContactKind::Falling { .. } => "N",
            },
            name: p.var_ref_name(*r),
        },
        Element::Compare { op, a, b } => boxed(vec![format!(
            "{} {} {}",
            operand(p, a),
            op.symbol(),
            operand(p, b)
        )]),
        Element::Or(_) | Element::Branch(_) => Shape::Parallel,
        Element::Coil { var: v, negated } => Shape::Coil {
            mark: if *negated { "/" } else { "" },
            name: var(v),
        },
        Element::Set(v) => Shape::Coil {
            mark: "S",
            name: var(v),
        },
        Element::Reset(v) => Shape::Coil {
            mark: "R",
            name: var(v),
        },
        Element::Timer { kind, instance, pt } => boxed(vec![
            format!("{} {}", kind.name().to_uppercase(), var(instance)),
            format!("PT {}", operand(p, pt)),
        ]),
        Element::Bistable {
            kind,
            instance,
            reset,
        } => boxed(vec![
            format!(
                "{} {}",
                match kind {
                    plc_model::BistableKind::SetDominant => "SR",
                    plc_model::BistableKind::ResetDominant => "RS",
                },
                var(instance)
            ),
            format!("R {}", operand(p, reset)),
        ]),
        Element::Trigger { kind, instance } => boxed(vec![format!(
            "{} {}",
            match kind {
                plc_model::TriggerKind::Rising => "R_TRIG",
                plc_model::TriggerKind::Falling => "F_TRIG",
            },
            var(instance)
        )]),
        Element::Ctud { instance, inputs } => boxed(vec![
            format!("CTUD {}", var(instance)),
            format!("CD {}", operand(p, &inputs.cd)),
            format!("R {}", operand(p, &inputs.reset)),
            format!("LD {}", operand(p, &inputs.load)),
            format!("PV {}", operand(p, &inputs.pv)),
        ]),
        Element::Ctu {
            instance,
            pv,
            reset,
        } => boxed(vec![
            format!("CTU {}", var(instance)),
            format!("PV {}", operand(p, pv)),
            format!("R {}", operand(p, reset)),
        ]),
        Element::Ctd { instance, pv, load } => boxed(vec![
            format!("CTD {}", var(instance)),
            format!("PV {}", operand(p, pv)),
            format!("LD {}", operand(p, load)),
        ]),
        Element::Move { from, to } => boxed(vec![
            "MOVE".into(),
            format!("{} → {}", operand(p, from), var(to)),
        ]),
        Element::Arith { op, a, b, out } => boxed(vec![
            op.name().into(),
            format!("{}, {} → {}", operand(p, a), operand(p, b), var(out)),
        ]),
        Element::Function { func, args, out } => {
            let args: Vec<String> = args.iter().map(|a| operand(p, a)).collect();
            boxed(vec![
                func.name(),
                format!("{} → {}", args.join(", "), var(out)),
            ])
        }
        Element::Jmp { label, .. } => Shape::Coil {
            mark: ">>",
            name: label.clone(),
        },
        Element::Ret => Shape::Coil {
            mark: "RET",
            name: String::new(),
        },
        Element::End => Shape::Coil {
            mark: "END",
            name: String::new(),
        },
        Element::Call { pou } => boxed(vec![format!("CALL {}", p.pou(*pou).name)]),
        Element::For { var: v, bounds, .. } => boxed(vec![
            "FOR".into(),
            format!(
                "{} := {} TO {}",
                var(v),
                operand(p, &bounds.from),
                operand(p, &bounds.to)
            ),
        ]),
        Element::Next { .. } => boxed(vec!["NEXT".into()]),
        Element::RangeFault => boxed(vec!["FAULT".into(), "index-range".into()]),
    }
}

fn branches(e: &Element) -> &[Series] {
    match e {
        Element::Or(bs) | Element::Branch(bs) => bs,
        _ => &[],
    }
}

fn element_size(p: &Program, e: &Element) -> Size {
    match shape(p, e) {
        Shape::Contact { name, .. } | Shape::Coil { name, .. } => Size {
            w: (text_w(&name) + 10.0).max(56.0),
            h: ROW,
        },
        Shape::Box { lines } => Size {
            w: lines.iter().map(|l| text_w(l)).fold(0.0, f64::max) + 28.0,
            h: (WIRE + 6.0 + 12.0 * lines.len() as f64).max(ROW),
        },
        Shape::Parallel => {
            let sizes: Vec<Size> = branches(e).iter().map(|b| series_size(p, b)).collect();
            Size {
                w: sizes.iter().map(|s| s.w).fold(0.0, f64::max) + 24.0,
                h: sizes.iter().map(|s| s.h).sum::<f64>().max(ROW),
            }
        }
    }
}

fn series_size(p: &Program, s: &[Element]) -> Size {
    let sizes = s.iter().map(|e| element_size(p, e));
    let (w, h) = sizes.fold((0.0, ROW), |(w, h), z| (w + z.w, f64::max(h, z.h)));
    Size {
        w: f64::max(w, 24.0),
        h,
    }
}

/// The size of `rung`'s ladder drawing, rails included.
pub(super) fn rung_size(p: &Program, rung: &Rung) -> Size {
    let s = series_size(p, &rung.series);
    Size {
        w: s.w + 2.0 * RAIL + 16.0,
        h: s.h + 4.0,
    }
}

fn line(out: &mut impl Write, x1: f64, y1: f64, x2: f64, y2: f64) -> io::Result<()> {
    writeln!(
        out,
        r#"<line x1="{x1:.1}" y1="{y1:.1}" x2="{x2:.1}" y2="{y2:.1}"/>"#
    )
}

fn text(out: &mut impl Write, x: f64, y: f64, anchor: &str, s: &str) -> io::Result<()> {
    writeln!(
        out,
        r#"<text x="{x:.1}" y="{y:.1}" text-anchor="{anchor}">{}</text>"#,
        esc(s)
    )
}

/// Draws `rung` with its top-left corner at the origin, as wide as [`rung_size`] says or as
/// `width` if that is wider (the wires stretch).
pub(super) fn draw_rung(
    out: &mut impl Write,
    p: &Program,
    rung: &Rung,
    width: f64,
) -> io::Result<()> {
    let natural = rung_size(p, rung);
    let size = Size {
        w: natural.w.max(width),
        h: natural.h,
    };
    out.write_all(b"<g class=\"ld\">\n")?;
    line(out, 1.0, 0.0, 1.0, size.h)?;
    line(out, size.w - 1.0, 0.0, size.w - 1.0, size.h)?;
    if rung.series.is_empty() {
        line(out, 1.0, WIRE, size.w - 1.0, WIRE)?;
        text(out, size.w / 2.0, WIRE - 4.0, "middle", "(empty)")?;
    } else {
        draw_series(out, p, &rung.series, 1.0, 0.0, size.w - 2.0)?;
    }
    out.write_all(b"</g>\n")
}

/// True for the elements a ladder editor puts at the right of a rung (coils, jumps, returns).
fn is_output(e: &Element) -> bool {
    matches!(
        e,
        Element::Coil { .. }
            | Element::Set(_)
            | Element::Reset(_)
            | Element::Jmp { .. }
            | Element::Ret
            | Element::End
    )
}

/// Draws a series from `(x, y)` filling `width`: extra width goes to a last parallel group,
/// or as wire before a last output, or as wire at the end.
fn draw_series(
    out: &mut impl Write,
    p: &Program,
    s: &[Element],
    x: f64,
    y: f64,
    width: f64,
) -> io::Result<()> {
    let sizes: Vec<Size> = s.iter().map(|e| element_size(p, e)).collect();
    let natural: f64 = sizes.iter().map(|z| z.w).sum();
    let extra = (width - natural).max(0.0);
    let mut cx = x;
    for (i, (e, z)) in s.iter().zip(&sizes).enumerate() {
        let last = i + 1 == s.len();
        let mut w = z.w;
        if last && matches!(e, Element::Or(_) | Element::Branch(_)) {
            w += extra;
        } else if last && is_output(e) {
            line(out, cx, y + WIRE, cx + extra, y + WIRE)?;
            cx += extra;
        }
        draw_element(out, p, e, cx, y, w)?;
        cx += w;
    }
    if cx < x + width {
        line(out, cx, y + WIRE, x + width, y + WIRE)?;
    }
    Ok(())
}

fn draw_element(
    out: &mut impl Write,
    p: &Program,
    e: &Element,
    x: f64,
    y: f64,
    w: f64,
) -> io::Result<()> {
    let wy = y + WIRE;
    let mid = x + w / 2.0;
    match shape(p, e) {
        Shape::Contact { mark, name } => {
            line(out, x, wy, mid - 7.0, wy)?;
            line(out, mid - 7.0, wy - 9.0, mid - 7.0, wy + 9.0)?;
            line(out, mid + 7.0, wy - 9.0, mid + 7.0, wy + 9.0)?;
            line(out, mid + 7.0, wy, x + w, wy)?;
            if !mark.is_empty() {
                text(out, mid, wy + 3.5, "middle", mark)?;
            }
            text(out, mid, y + 9.0, "middle", &name)
        }
        Shape::Coil { mark, name } => {
            let r = if mark.len() > 2 { 13.0 } else { 8.0 };
            line(out, x, wy, mid - r, wy)?;
            writeln!(
                out,
                r#"<path d="M{:.1} {:.1}q-5 9 0 18M{:.1} {:.1}q5 9 0 18"/>"#,
                mid - r + 2.0,
                wy - 9.0,
                mid + r - 2.0,
                wy - 9.0
            )?;
            line(out, mid + r, wy, x + w, wy)?;
            if !mark.is_empty() {
                text(out, mid, wy + 3.5, "middle", mark)?;
            }
            text(out, mid, y + 9.0, "middle", &name)
        }
        Shape::Box { lines } => {
            line(out, x, wy, x + 8.0, wy)?;
            line(out, x + w - 8.0, wy, x + w, wy)?;
            let h = 6.0 + 12.0 * lines.len() as f64;
            writeln!(
                out,
                r#"<rect x="{:.1}" y="{:.1}" width="{:.1}" height="{h:.1}" rx="2"/>"#,
                x + 8.0,
                wy - 8.0,
                w - 16.0
            )?;
            for (i, l) in lines.iter().enumerate() {
                text(out, mid, wy + 2.0 + 12.0 * i as f64, "middle", l)?;
            }
            Ok(())
        }
        Shape::Parallel => draw_parallel(out, p, branches(e), x, y, w),
    }
}

/// Branches stacked under each other between a left and a right vertical join.
fn draw_parallel(
    out: &mut impl Write,
    p: &Program,
    bs: &[Series],
    x: f64,
    y: f64,
    w: f64,
) -> io::Result<()> {
    let (left, right) = (x + 6.0, x + w - 6.0);
    line(out, x, y + WIRE, left, y + WIRE)?;
    line(out, right, y + WIRE, x + w, y + WIRE)?;
    let mut by = y;
    let mut last_wire = y + WIRE;
    for b in bs {
        let h = series_size(p, b).h;
        line(out, left, by + WIRE, left + 6.0, by + WIRE)?;
        draw_series(out, p, b, left + 6.0, by, w - 24.0)?;
        line(out, right - 6.0, by + WIRE, right, by + WIRE)?;
        last_wire = by + WIRE;
        by += h;
    }
    line(out, left, y + WIRE, left, last_wire)?;
    line(out, right, y + WIRE, right, last_wire)
}

/// What feeds an input pin, as the card writes it.
fn source(net: &Network, i: &Input) -> String {
    match i {
        Input::Variable(v) => v.clone(),
        Input::Constant(c) => c.text(),
        Input::Arc { from, pin } => {
            let b = net.block(*from);
            let name = b
                .outputs
                .get(*pin as usize)
                .map(|o| o.name.as_str())
                .unwrap_or("OUT");
            format!("#{}.{name}", b.id)
        }
    }
}

/// The rows of a block's drawing: (source, input pin) on the left, (output pin, variables) on
/// the right, and its title.
struct BlockRows {
    title: String,
    ins: Vec<(String, String)>,
    outs: Vec<(String, String)>,
}

fn block_rows(net: &Network, b: &Block) -> BlockRows {
    let mut title = format!("#{} {}", b.id, b.op.name());
    if let Some(i) = b.op.instance() {
        title.push(' ');
        title.push_str(i);
    }
    if let plc_fbd::Op::Jmp { label } = &b.op {
        title.push_str(&format!(" → {label}"));
    }
    let mut ins: Vec<(String, String)> = b
        .inputs
        .iter()
        .map(|pin| {
            let src = pin
                .input
                .as_ref()
                .map(|i| source(net, i))
                .unwrap_or_default();
            (src, pin.name.clone())
        })
        .collect();
    if let Some(c) = &b.cond {
        let pin = if b.cond_is_own() { "COND" } else { "EN" };
        ins.push((source(net, c), pin.into()));
    }
    let outs = b
        .outputs
        .iter()
        .map(|o| {
            let vars: Vec<&str> = o.vars.iter().map(|(v, _)| v.as_str()).collect();
            (o.name.clone(), vars.join(", "))
        })
        .collect();
    BlockRows { title, ins, outs }
}

fn block_geometry(r: &BlockRows) -> (f64, f64, f64, Size) {
    let left = r.ins.iter().map(|(s, _)| text_w(s)).fold(0.0, f64::max) + 12.0;
    let pins = r.ins.iter().map(|(_, n)| text_w(n)).fold(0.0, f64::max)
        + r.outs.iter().map(|(n, _)| text_w(n)).fold(0.0, f64::max)
        + 16.0;
    let boxw = f64::max(text_w(&r.title) + 12.0, pins);
    let right = r.outs.iter().map(|(_, v)| text_w(v)).fold(0.0, f64::max) + 12.0;
    let rows = r.ins.len().max(r.outs.len()).max(1) as f64;
    let h = 20.0 + 13.0 * rows + 6.0;
    (
        left,
        boxw,
        right,
        Size {
            w: left + boxw + right,
            h,
        },
    )
}

/// The size of a block's drawing.
pub(super) fn block_size(net: &Network, b: &Block) -> Size {
    block_geometry(&block_rows(net, b)).3
}

/// Draws an FBD block with its top-left corner at the origin.
pub(super) fn draw_block(out: &mut impl Write, net: &Network, b: &Block) -> io::Result<()> {
    let rows = block_rows(net, b);
    let (left, boxw, _, size) = block_geometry(&rows);
    out.write_all(b"<g class=\"ld fbd\">\n")?;
    writeln!(
        out,
        r#"<rect x="{left:.1}" y="1" width="{boxw:.1}" height="{:.1}" rx="2"/>"#,
        size.h - 2.0
    )?;
    text(out, left + boxw / 2.0, 14.0, "middle", &rows.title)?;
    for (i, (src, pin)) in rows.ins.iter().enumerate() {
        let y = 20.0 + 13.0 * i as f64 + 8.0;
        line(out, left - 8.0, y, left, y)?;
        text(out, left - 10.0, y + 3.5, "end", src)?;
        text(out, left + 3.0, y + 3.5, "start", pin)?;
    }
    for (i, (pin, vars)) in rows.outs.iter().enumerate() {
        let y = 20.0 + 13.0 * i as f64 + 8.0;
        let r = left + boxw;
        line(out, r, y, r + 8.0, y)?;
        text(out, r - 3.0, y + 3.5, "end", pin)?;
        text(out, r + 10.0, y + 3.5, "start", vars)?;
    }
    out.write_all(b"</g>\n")
}
