//! User function block types kept in the resolved program (crates/plc-fbd/src/types.rs): each type's
//! interface, its instances, and its FBD body with typed pins — arcs, variables named relative
//! to the type (own inputs, outputs and locals, members of nested instances, program
//! variables) and constants typed by their blocks.

use plc_deps::fbd::*;
use plc_deps::model::{Field, Program, Type, Value, VarId};
use serde_json::json;

fn load(text: &str) -> (Program, Fbd) {
    plc_deps::load::program_and_fbd_from_json(text).expect("the program loads")
}

fn own(slot: Slot) -> TypedRef {
    TypedRef {
        var: TypedVar::Own(slot),
        field: None,
    }
}

fn var(r: TypedRef) -> Option<Pin> {
    Some(Pin::Variable(r))
}

fn constant(v: Value) -> Option<Pin> {
    Some(Pin::Constant(v))
}

fn arc(block: u32, output: u32) -> Option<Pin> {
    Some(Pin::Arc {
        block: BlockId::from_raw(block),
        output,
    })
}

fn block(inputs: Vec<Option<Pin>>, cond: Option<Pin>, outputs: Vec<Vec<TypedRef>>) -> TypedBlock {
    TypedBlock {
        inputs,
        cond,
        outputs,
    }
}

fn typed(t: &FbType) -> &TypedBody {
    match &t.body {
        FbTypeBody::Fbd {
            typed: Some(body), ..
        } => body,
        other => panic!("{} has no typed FBD body: {other:?}", t.name),
    }
}

#[test]
fn kaskad_5_keeps_the_generator_type_its_two_instances_and_typed_pins() {
    let text = std::fs::read_to_string("analyses/kaskad-5/program.json").expect("example");
    let (p, fbd) = load(&text);
    assert_eq!(fbd.types.len(), 1);
    let g = &fbd.types[0];
    assert_eq!(g.name, "GENERATOR");
    let v = |name: &str, ty, init| FbVar {
        name: name.into(),
        ty,
        init,
    };
    assert_eq!(g.inputs, vec![v("PERIOD", Type::Time, Value::Time(0))]);
    assert_eq!(g.outputs, vec![v("RESULT", Type::Int, Value::Int(0))]);
    assert_eq!(g.locals, vec![v("GEN_TIMER", Type::Time, Value::Time(0))]);
    assert!(g.nested.is_empty());
    let FbTypeBody::Fbd { pou, .. } = g.body else {
        panic!("GENERATOR has an FBD body");
    };
    assert_eq!(fbd.pous[pou].name, "GENERATOR");
    assert_eq!(fbd.pous[pou].kind, FbdPouKind::FunctionBlock);
    let instances: Vec<(&str, &str, FbTypeId, &str)> = fbd
        .instances
        .iter()
        .map(|i| {
            (
                i.name.as_str(),
                i.fb.as_str(),
                i.ty,
                p.pou(i.pou).name.as_str(),
            )
        })
        .collect();
    assert_eq!(
        instances,
        vec![
            ("Gen1", "GENERATOR", FbTypeId::from_raw(0), "Gen1"),
            ("Gen2", "GENERATOR", FbTypeId::from_raw(0), "Gen2")
        ]
    );
    // Network G: 1 EQ(GEN_TIMER, T#0s); 2 TSTART(GEN_TIMER) if 1; 3 LT(GEN_TIMER, PERIOD);
    // 4 RET if 3; 5 TSTOP(GEN_TIMER); 6 MOVE(T#0s) → GEN_TIMER; 7 SUB(1, RESULT) → RESULT.
    let timer = own(Slot::Local(0));
    let result = own(Slot::Output(0));
    let body = typed(g);
    assert_eq!(body.networks.len(), 1);
    assert_eq!(
        body.networks[0].blocks,
        vec![
            block(
                vec![var(timer), constant(Value::Time(0))],
                None,
                vec![vec![]]
            ),
            block(vec![var(timer)], arc(0, 0), vec![]),
            block(
                vec![var(timer), var(own(Slot::Input(0)))],
                None,
                vec![vec![]]
            ),
            block(vec![], arc(2, 0), vec![]),
            block(vec![var(timer)], None, vec![]),
            block(vec![constant(Value::Time(0))], None, vec![vec![timer]]),
            block(
                vec![constant(Value::Int(1)), var(result)],
                None,
                vec![vec![result]]
            ),
        ]
    );
}

#[test]
fn nested_instances_timers_and_program_variables_are_named_relative_to_the_type() {
    let doc = json!({"program": "t",
        "vars": [{"name": "p", "type": "BOOL", "class": "input"}, {"name": "K", "type": "INT"},
                 {"name": "W", "type": "WRAP"}, {"name": "r", "type": "INT"}],
        "function_blocks": {
            "COUNTER": {
                "inputs": [{"name": "EN", "type": "BOOL"}, {"name": "STEP", "type": "INT", "init": 1}],
                "outputs": [{"name": "OUT", "type": "INT"}],
                "vars": [{"name": "N", "type": "INT"}],
                "rungs": [{"id": "R1", "ld": [{"contact": "EN", "edge": "rising"}, {"op": "ADD", "in": ["N", "STEP"], "out": "N"}]},
                          {"id": "R2", "ld": [{"move": "N", "to": "OUT"}]}]},
            "WRAP": {
                "inputs": [{"name": "GO", "type": "BOOL"}],
                "outputs": [{"name": "RES", "type": "INT"}],
                "vars": [{"name": "T", "type": "TON"}, {"name": "INNER", "type": "COUNTER"},
                         {"name": "L", "type": "REAL", "init": 1.5}],
                "fbd": {"networks": [{"id": "W1", "blocks": [
                    {"id": 1, "op": "TON", "instance": "T", "in": ["GO", "T#2s"]},
                    {"id": 2, "op": "COUNTER", "instance": "INNER", "in": {"EN": {"from": 1}, "STEP": 5}},
                    {"id": 3, "op": "ADD", "in": [{"from": 2}, "INNER.OUT", "K"], "out": "RES", "cond": "T.Q"},
                    {"id": 4, "op": "MOVE", "in": [2.5], "out": ["L"]}]}]}},
            "UNUSED": {
                "inputs": [{"name": "A", "type": "INT"}], "outputs": [{"name": "B", "type": "INT"}],
                "fbd": {"networks": [{"id": "U1", "blocks": [{"id": 1, "op": "MOVE", "in": ["A"], "out": "B"}]}]}}},
        "fbd": {"networks": [{"id": "N1", "blocks": [
            {"id": 1, "op": "WRAP", "instance": "W", "in": ["p"], "out": "r"}]}]}});
    let (p, fbd) = load(&doc.to_string());
    let names: Vec<&str> = fbd.types.iter().map(|t| t.name.as_str()).collect();
    assert_eq!(names, vec!["COUNTER", "WRAP", "UNUSED"]);
    assert_eq!(fbd.types[0].body, FbTypeBody::Ladder);
    let w = &fbd.types[1];
    let v = |name: &str, ty, init| FbVar {
        name: name.into(),
        ty,
        init,
    };
    assert_eq!(w.inputs, vec![v("GO", Type::Bool, Value::Bool(false))]);
    assert_eq!(w.outputs, vec![v("RES", Type::Int, Value::Int(0))]);
    let locals: Vec<(&str, Type)> = w.locals.iter().map(|l| (l.name.as_str(), l.ty)).collect();
    assert_eq!(
        locals,
        vec![
            ("T", Type::Fb(plc_deps::model::FbKind::Ton)),
            ("L", Type::Real)
        ]
    );
    assert_eq!(w.locals[1].init, Value::Real(1.5));
    assert_eq!(
        w.nested,
        vec![Nested {
            name: "INNER".into(),
            ty: FbTypeId::from_raw(0)
        }]
    );
    let instances: Vec<(&str, FbTypeId)> = fbd
        .instances
        .iter()
        .map(|i| (i.name.as_str(), i.ty))
        .collect();
    assert_eq!(
        instances,
        vec![
            ("W", FbTypeId::from_raw(1)),
            ("W.INNER", FbTypeId::from_raw(0))
        ]
    );
    let k = VarId::from_raw(p.vars().iter().position(|v| v.name == "K").expect("K") as u32);
    let t = Slot::Local(0);
    let t_q = TypedRef {
        var: TypedVar::Own(t),
        field: Some(Field::Q),
    };
    let inner_out = TypedRef {
        var: TypedVar::Member {
            nested: 0,
            slot: Slot::Output(0),
        },
        field: None,
    };
    let global_k = TypedRef {
        var: TypedVar::Global(k),
        field: None,
    };
    assert_eq!(
        typed(w).networks[0].blocks,
        vec![
            block(
                vec![var(own(Slot::Input(0))), constant(Value::Time(2000))],
                None,
                vec![vec![], vec![]]
            ),
            block(vec![arc(0, 0), constant(Value::Int(5))], None, vec![vec![]]),
            block(
                vec![arc(1, 0), var(inner_out), var(global_k)],
                var(t_q),
                vec![vec![own(Slot::Output(0))]]
            ),
            block(
                vec![constant(Value::Real(2.5))],
                None,
                vec![vec![own(Slot::Local(1))]]
            ),
        ]
    );
    // A type nothing instantiates keeps its interface and networks, but no typed form.
    let u = &fbd.types[2];
    assert_eq!(u.inputs, vec![v("A", Type::Int, Value::Int(0))]);
    match &u.body {
        FbTypeBody::Fbd { pou, typed: None } => assert_eq!(fbd.pous[*pou].name, "UNUSED"),
        other => panic!("UNUSED: {other:?}"),
    }
}
