//! The surface syntax as the JSON program format (docs/format.md, docs/fbd.md): one object per
//! POU with its keys in the format's order, one variable, rung, network or block per line, so
//! that a converted file reads and diffs like a hand-written one.
//!
//! Every node is written as the JSON reader reads it ([`plc_read::json`]): operands as
//! written (a name or TIME literal as a string, numbers and booleans as themselves), optional
//! keys only when the syntax has them. A part the reader found malformed ([`Problem`]) cannot be
//! written: the writer stops with an `InvalidData` error naming it (the caller loads the
//! program first, so this does not happen on a program that loads).
//!
//! Deliberately not here: comments of variables and of elements (the syntax does not keep
//! them), positions and the editor's layout (the JSON format has neither).

use plc_syntax::fbd::{
    Block, Connection, FbdBody, Input, Inputs, Network, OutVar, Outputs, Read, Targets,
};
use plc_syntax::{
    Body, Edge, Element, ElementKind, FunctionBlock, Problem, Program, RoutineKind, Rung, Scalar,
    Series, Subroutine, Var, VarClass,
};
use serde_json::{json, Map, Value};
use std::io::{self, Write};

/// Writes `p` as the JSON program format.
pub fn program(p: &Program, w: &mut impl Write) -> io::Result<()> {
    if let Some(problem) = p.problems.first() {
        return Err(malformed(problem));
    }
    write!(w, "{{\"program\": {}", string(&p.name))?;
    if let Some(c) = &p.comment {
        write!(w, ",\n\"comment\": {}", string(c))?;
    }
    write!(w, ",\n\"vars\": ")?;
    vars(&p.vars, w, "")?;
    if let Some(b) = &p.body {
        writeln!(w, ",")?;
        body(b, w, "")?;
    }
    for (key, kind) in [
        ("subroutines", RoutineKind::Subroutine),
        ("interrupts", RoutineKind::Interrupt),
    ] {
        let mut routines = p.subroutines.iter().filter(|s| s.kind == kind).peekable();
        if routines.peek().is_none() {
            continue;
        }
        write!(w, ",\n\"{key}\": {{")?;
        for (i, s) in routines.enumerate() {
            write!(w, "{}\n  {}: ", comma(i), string(&s.name))?;
            subroutine(s, w)?;
        }
        write!(w, "\n}}")?;
    }
    if !p.function_blocks.is_empty() {
        write!(w, ",\n\"function_blocks\": {{")?;
        for (i, f) in p.function_blocks.iter().enumerate() {
            write!(w, "{}\n  {}: ", comma(i), string(&f.name))?;
            function_block(f, w)?;
        }
        write!(w, "\n}}")?;
    }
    if let Some(c) = &p.configuration {
        write!(w, ",\n\"configuration\": ")?;
        configuration(c, w)?;
    }
    if p.dialect != plc_model::Dialect::default() {
        write!(w, ",\n\"dialect\": {}", string(p.dialect.name()))?;
    }
    writeln!(w, "\n}}")
}

/// The configuration: its own line, one line per resource (tasks and instances as the report's
/// `configuration` key has them, optional attributes only when present).
fn configuration(c: &plc_model::Configuration, w: &mut impl Write) -> io::Result<()> {
    write!(w, "{{\"name\": {}, \"resources\": ", string(&c.name))?;
    let items: Vec<Value> = c
        .resources
        .iter()
        .map(|r| serde_json::to_value(r).map_err(io::Error::other))
        .collect::<io::Result<_>>()?;
    lines(&items, w, "")?;
    write!(w, "}}")
}

fn subroutine(s: &Subroutine, w: &mut impl Write) -> io::Result<()> {
    write!(w, "{{\"vars\": ")?;
    vars(&s.vars, w, "    ")?;
    if let Some(b) = &s.body {
        write!(w, ",\n    ")?;
        body(b, w, "    ")?;
    }
    write!(w, "}}")
}

fn function_block(f: &FunctionBlock, w: &mut impl Write) -> io::Result<()> {
    write!(w, "{{\"inputs\": ")?;
    vars(&f.inputs, w, "    ")?;
    write!(w, ",\n    \"outputs\": ")?;
    vars(&f.outputs, w, "    ")?;
    write!(w, ",\n    \"vars\": ")?;
    vars(&f.vars, w, "    ")?;
    if let Some(b) = &f.body {
        write!(w, ",\n    ")?;
        body(b, w, "    ")?;
    }
    write!(w, "}}")
}

/// `"rungs": [...]` or `"fbd": {...}`.
fn body(b: &Body, w: &mut impl Write, indent: &str) -> io::Result<()> {
    match b {
        Body::Rungs(rungs) => {
            write!(w, "\"rungs\": ")?;
            let items: Vec<Value> = rungs.iter().map(rung).collect::<io::Result<_>>()?;
            lines(&items, w, indent)
        }
        Body::Fbd(f) => {
            write!(w, "\"fbd\": ")?;
            fbd(f, w, indent)
        }
    }
}

/// A JSON array with one item per line.
fn lines(items: &[Value], w: &mut impl Write, indent: &str) -> io::Result<()> {
    if items.is_empty() {
        return write!(w, "[]");
    }
    write!(w, "[")?;
    for (i, item) in items.iter().enumerate() {
        write!(w, "{}\n{indent}  {item}", comma(i))?;
    }
    write!(w, "\n{indent}]")
}

fn comma(i: usize) -> &'static str {
    if i == 0 {
        ""
    } else {
        ","
    }
}

fn string(s: &str) -> Value {
    Value::String(s.to_owned())
}

fn malformed(p: &Problem) -> io::Error {
    io::Error::new(
        io::ErrorKind::InvalidData,
        format!("a malformed part cannot be written ({}{})", p.at, p.kind),
    )
}

fn read<T>(r: &Read<T>) -> io::Result<&T> {
    r.as_ref().map_err(|p| malformed(p))
}

fn vars(vs: &[Var], w: &mut impl Write, indent: &str) -> io::Result<()> {
    let items: Vec<Value> = vs.iter().map(var).collect::<io::Result<_>>()?;
    lines(&items, w, indent)
}

fn var(v: &Var) -> io::Result<Value> {
    if let Some(p) = &v.problem {
        return Err(malformed(p));
    }
    let mut o = Map::new();
    o.insert("name".into(), string(v.name.as_str()));
    o.insert("type".into(), string(v.ty.as_str()));
    let class = match v.class.value {
        VarClass::Input => Some("input"),
        VarClass::Output => Some("output"),
        VarClass::Memory => Some("memory"),
        VarClass::Default => None,
    };
    if let Some(c) = class {
        o.insert("class".into(), string(c));
    }
    if let Some(init) = &v.init {
        o.insert("init".into(), operand(&init.value));
    }
    Ok(Value::Object(o))
}

fn operand(s: &Scalar) -> Value {
    match s {
        Scalar::Null => Value::Null,
        Scalar::Bool(b) => Value::Bool(*b),
        Scalar::Number(n) => Value::Number(n.clone()),
        Scalar::Str(t) => string(t),
        Scalar::Array => Value::Array(Vec::new()),
        Scalar::Object => Value::Object(Map::new()),
    }
}

fn rung(r: &Rung) -> io::Result<Value> {
    if let Some(p) = &r.problem {
        return Err(malformed(p));
    }
    let mut o = Map::new();
    o.insert("id".into(), string(r.id.as_str()));
    if let Some(l) = &r.label {
        o.insert("label".into(), string(l.as_str()));
    }
    if let Some(c) = &r.comment {
        o.insert("comment".into(), string(c));
    }
    o.insert("ld".into(), series(&r.ld)?);
    Ok(Value::Object(o))
}

fn series(s: &Series) -> io::Result<Value> {
    s.iter()
        .map(element)
        .collect::<io::Result<Vec<_>>>()
        .map(Value::Array)
}

fn branches(bs: &[Series]) -> io::Result<Value> {
    bs.iter()
        .map(series)
        .collect::<io::Result<Vec<_>>>()
        .map(Value::Array)
}

fn element(e: &Element) -> io::Result<Value> {
    use ElementKind as K;
    Ok(match &e.kind {
        K::Contact { var, negated, edge } => {
            let mut o = Map::new();
            o.insert("contact".into(), string(var.as_str()));
            if *negated {
                o.insert("negated".into(), Value::Bool(true));
            }
            if let Some(edge) = edge {
                let e = match edge {
                    Edge::Rising => "rising",
                    Edge::Falling => "falling",
                };
                o.insert("edge".into(), string(e));
            }
            Value::Object(o)
        }
        K::Compare(c) => json!({
            "compare": c.op.name(), "a": operand(&c.a.value), "b": operand(&c.b.value)
        }),
        K::Or(bs) => json!({ "or": branches(bs)? }),
        K::Coil { var, negated } => match negated {
            true => json!({ "coil": var.as_str(), "negated": true }),
            false => json!({ "coil": var.as_str() }),
        },
        K::Set(v) => json!({ "set": v.as_str() }),
        K::Reset(v) => json!({ "reset": v.as_str() }),
        K::Branch(bs) => json!({ "branch": branches(bs)? }),
        K::Timer(t) => {
            let mut o = Map::new();
            o.insert(t.kind.name().into(), string(t.instance.as_str()));
            o.insert("pt".into(), operand(&t.pt.value));
            Value::Object(o)
        }
        K::Counter(c) => match c.down {
            false => json!({
                "ctu": c.instance.as_str(), "pv": operand(&c.pv.value),
                "reset": operand(&c.aux.value)
            }),
            true => json!({
                "ctd": c.instance.as_str(), "pv": operand(&c.pv.value),
                "load": operand(&c.aux.value)
            }),
        },
        K::Bistable(b) => {
            let key = match b.kind {
                plc_model::BistableKind::SetDominant => "sr",
                plc_model::BistableKind::ResetDominant => "rs",
            };
            let mut o = Map::new();
            o.insert(key.into(), string(b.instance.as_str()));
            o.insert("reset".into(), operand(&b.reset.value));
            Value::Object(o)
        }
        K::Trigger { kind, instance } => match kind {
            plc_model::TriggerKind::Rising => json!({ "r_trig": instance.as_str() }),
            plc_model::TriggerKind::Falling => json!({ "f_trig": instance.as_str() }),
        },
        K::Ctud(c) => json!({
            "ctud": c.instance.as_str(), "cd": operand(&c.cd.value),
            "reset": operand(&c.reset.value), "load": operand(&c.load.value),
            "pv": operand(&c.pv.value)
        }),
        K::Move(m) => json!({ "move": operand(&m.from.value), "to": m.to.as_str() }),
        K::Function(c) => json!({
            "op": c.func.name(),
            "in": c.args.iter().map(|a| operand(&a.value)).collect::<Vec<_>>(),
            "out": c.out.as_str(),
        }),
        K::Arith(a) => json!({
            "op": a.op.name(), "in": [operand(&a.a.value), operand(&a.b.value)],
            "out": a.out.as_str()
        }),
        K::Jmp(l) => json!({ "jmp": l.as_str() }),
        K::Ret => json!({ "ret": true }),
        K::End => json!({ "end": true }),
        K::Call(s) => json!({ "call": s.as_str() }),
        K::For(f) => json!({
            "for": {"var": f.var.as_str(), "from": operand(&f.from.value),
                    "to": operand(&f.to.value)}
        }),
        K::Next => json!({ "next": true }),
        K::RangeFault => json!({ "range_fault": true }),
        K::Invalid(p) => return Err(malformed(p)),
    })
}

fn fbd(f: &FbdBody, w: &mut impl Write, indent: &str) -> io::Result<()> {
    if let Some(p) = &f.problem {
        return Err(malformed(p));
    }
    write!(w, "{{")?;
    if let Some(c) = &f.comment {
        write!(w, "\"comment\": {}, ", string(c))?;
    }
    write!(w, "\"networks\": [")?;
    for (i, n) in f.networks.iter().enumerate() {
        write!(w, "{}\n{indent}  ", comma(i))?;
        network(n, w, &format!("{indent}  "))?;
    }
    write!(w, "\n{indent}]}}")
}

fn network(n: &Network, w: &mut impl Write, indent: &str) -> io::Result<()> {
    if let Some(p) = &n.problem {
        return Err(malformed(p));
    }
    write!(w, "{{\"id\": {}", string(read(&n.id)?))?;
    if let Some(l) = &n.label {
        write!(w, ", \"label\": {}", string(read(l)?))?;
    }
    if let Some(c) = &n.comment {
        write!(w, ", \"comment\": {}", string(read(c)?))?;
    }
    if let Some(o) = &n.order {
        let ids = read(o)?
            .iter()
            .map(|id| read(id).map(|&id| Value::from(id)))
            .collect::<io::Result<_>>()?;
        write!(w, ", \"order\": {}", Value::Array(ids))?;
    }
    write!(w, ", \"blocks\": ")?;
    let items: Vec<Value> = read(&n.blocks)?
        .iter()
        .map(block)
        .collect::<io::Result<_>>()?;
    lines(&items, w, indent)?;
    write!(w, "}}")
}

fn block(b: &Block) -> io::Result<Value> {
    if let Some(p) = &b.problem {
        return Err(malformed(p));
    }
    let mut o = Map::new();
    o.insert("id".into(), Value::from(*read(&b.id)?));
    o.insert("op".into(), string(read(&b.op)?));
    if let Some(i) = &b.instance {
        o.insert("instance".into(), string(read(i)?));
    }
    if let Some(ins) = &b.inputs {
        let v = match read(ins)? {
            Inputs::List(list) => Value::Array(list.iter().map(input).collect::<io::Result<_>>()?),
            Inputs::Named(named) => Value::Object(
                named
                    .iter()
                    .map(|(pin, i)| Ok((pin.to_string(), input(i)?)))
                    .collect::<io::Result<_>>()?,
            ),
        };
        o.insert("in".into(), v);
    }
    if let Some(outs) = &b.outputs {
        o.insert("out".into(), outputs(read(outs)?)?);
    }
    if let Some(c) = &b.cond {
        let key = if b.en { "en" } else { "cond" };
        o.insert(key.into(), input(c)?);
    }
    if let Some(after) = &b.after {
        let ids = read(after)?
            .iter()
            .map(|id| read(id).map(|&id| Value::from(id)))
            .collect::<io::Result<_>>()?;
        o.insert("after".into(), Value::Array(ids));
    }
    if let Some(l) = &b.label {
        o.insert("label".into(), string(read(l)?));
    }
    if let Some(c) = &b.comment {
        o.insert("comment".into(), string(read(c)?));
    }
    Ok(Value::Object(o))
}

fn input(i: &Input) -> io::Result<Value> {
    Ok(match &i.from {
        Connection::Arc { block, pin } => match pin {
            Some(pin) => json!({ "from": block, "pin": read(pin)?.as_ref() }),
            None => json!({ "from": block }),
        },
        Connection::Variable(v) => string(v),
        Connection::Constant(c) => operand(c),
        Connection::Invalid(p) => return Err(malformed(p)),
    })
}

fn out_var(v: &OutVar) -> Value {
    string(&v.name)
}

fn outputs(o: &Outputs) -> io::Result<Value> {
    Ok(match o {
        Outputs::First(v) => out_var(v),
        Outputs::List(list) => Value::Array(
            list.iter()
                .map(|v| Ok(read(v)?.as_ref().map_or(Value::Null, out_var)))
                .collect::<io::Result<_>>()?,
        ),
        Outputs::Named(named) => Value::Object(
            named
                .iter()
                .map(|(pin, t)| {
                    let v = match read(t)? {
                        Targets::One(v) => out_var(v),
                        Targets::Many(vs) => Value::Array(
                            vs.iter()
                                .map(|v| read(v).map(out_var))
                                .collect::<io::Result<_>>()?,
                        ),
                    };
                    Ok((pin.to_string(), v))
                })
                .collect::<io::Result<_>>()?,
        ),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn converted(text: &str) -> String {
        let syn = plc_read::json::parse(text).expect("parses");
        let mut out = Vec::new();
        program(&syn, &mut out).expect("writes");
        String::from_utf8(out).unwrap()
    }

    #[test]
    fn every_element_kind_is_written_as_the_reader_reads_it() {
        let text = r#"{"program": "P", "comment": "c",
          "vars": [{"name": "A", "type": "BOOL", "class": "input"}, {"name": "B", "type": "BOOL"},
                   {"name": "N", "type": "INT", "init": 3}, {"name": "T1", "type": "TON"},
                   {"name": "C1", "type": "CTU"}, {"name": "C2", "type": "CTD"},
                   {"name": "B1", "type": "SR"}, {"name": "B2", "type": "RS"},
                   {"name": "E1", "type": "R_TRIG"}, {"name": "E2", "type": "F_TRIG"},
                   {"name": "U1", "type": "CTUD"}],
          "rungs": [
            {"id": "R1", "label": "L", "comment": "x", "ld": [{"contact": "A", "edge": "rising"},
              {"or": [[{"contact": "B", "negated": true}], [{"compare": "GE", "a": "N", "b": 2}]]},
              {"branch": [[{"coil": "B", "negated": true}], [{"set": "B"}], [{"reset": "B"}]]}]},
            {"id": "R2", "ld": [{"ton": "T1", "pt": "T#2s"}, {"ctu": "C1", "pv": 10, "reset": "A"},
              {"ctd": "C2", "pv": 5, "load": false}, {"move": 0, "to": "N"},
              {"op": "ADD", "in": ["N", 1], "out": "N"}, {"jmp": "L"}]},
            {"id": "R3", "ld": [{"for": {"var": "N", "from": 1, "to": 3}}]},
            {"id": "R4", "ld": [{"next": true}]},
            {"id": "R5", "ld": [{"call": "S"}, {"ret": true}]},
            {"id": "R6", "ld": [{"end": true}]},
            {"id": "R7", "ld": [{"sr": "B1", "reset": "A"}, {"rs": "B2", "reset": false},
              {"r_trig": "E1"}, {"f_trig": "E2"},
              {"ctud": "U1", "cd": "A", "reset": false, "load": "B", "pv": 4}]}],
          "subroutines": {"S": {"vars": [], "rungs": [{"id": "S1", "ld": [{"coil": "B"}]}]}}}"#;
        let out = converted(text);
        let a: Value = serde_json::from_str(text).unwrap();
        let b: Value = serde_json::from_str(&out).expect("the output is JSON");
        assert_eq!(a, b, "{out}");
        assert!(
            out.contains("\n  {\"id\":\"R2\""),
            "one rung per line: {out}"
        );
    }

    #[test]
    fn fbd_bodies_and_function_blocks_are_written_as_read() {
        let text = r#"{"program": "p",
          "vars": [{"name": "V1", "type": "INT", "class": "input"}, {"name": "L", "type": "INT"},
                   {"name": "R", "type": "INT"}, {"name": "G1", "type": "GEN"}],
          "fbd": {"comment": "body", "networks": [
            {"id": "N1", "label": "L2", "comment": "n", "order": [9, 3], "blocks": [
              {"id": 3, "op": "EQ", "in": ["V1", 1]},
              {"id": 8, "op": "ADD", "in": ["L", 10], "out": "L", "cond": {"from": 3}},
              {"id": 9, "op": "NOT", "in": [{"from": 3}]},
              {"id": 10, "op": "MOVE", "in": ["V1"], "out": "R", "en": {"from": 9}},
              {"id": 15, "op": "SUB", "in": ["L", 1], "after": [8], "comment": "b"},
              {"id": 17, "op": "GEN", "instance": "G1", "in": {"PERIOD": "T#1s"},
               "out": {"RESULT": "R"}},
              {"id": 18, "op": "MOVE", "in": [{"from": 17, "pin": "RESULT"}], "out": ["R"]}]}]},
          "function_blocks": {"GEN": {
            "inputs": [{"name": "PERIOD", "type": "TIME"}],
            "outputs": [{"name": "RESULT", "type": "INT"}], "vars": [],
            "fbd": {"networks": [{"id": "F1", "blocks": [
              {"id": 1, "op": "ADD", "in": ["RESULT", 1], "out": "RESULT"}]}]}}}}"#;
        let a: Value = serde_json::from_str(text).unwrap();
        let out = converted(text);
        let b: Value = serde_json::from_str(&out).expect("the output is JSON");
        assert_eq!(a, b, "{out}");
    }

    #[test]
    fn a_malformed_part_is_refused_not_written() {
        let syn = plc_read::json::parse(
            r#"{"program": "P", "vars": [], "rungs": [{"id": "R1", "ld": [{"bogus": 1}]}]}"#,
        )
        .unwrap();
        let e = program(&syn, &mut Vec::new()).unwrap_err();
        assert_eq!(e.kind(), io::ErrorKind::InvalidData);
    }
}
