//! FBD bodies (TC6 `FBD`) → the syntax's FBD body ([`plc_syntax::fbd`]), so that order,
//! fragments and lowering are the JSON format's (docs/fbd.md).
//!
//! Mapping: a `block` is a block with id = its localId, op = its `typeName`, its instance, its
//! inputs by pin name and its outputs by pin name; `EN` is the conditional arc (`cond`). An
//! input fed by a block is a data arc (`formalParameter` names the output pin; none: the first
//! output), by an `inVariable` a variable or a constant, by an `inOutVariable` its variable (so
//! a feedback loop closes through the variable, as Beremiz closes it). An `outVariable` or
//! `inOutVariable` fed by a block output is a variable that output writes; fed directly by a
//! variable it is a MOVE block with the out variable's localId. `jump` and `return` are JMP and
//! RET blocks whose condition is their input. A `label` starts a new network (networks
//! `<pou>.N1`, `<pou>.N2` … in file order; one network without labels is `<pou>`).
//! `connector`/`continuation` pairs are spliced by [`super::wiring`]; the text of the
//! `comment`s of a network, in file order, is its comment.
//!
//! Order: the FBD text-generation paper's depth-first topological sort over the arcs, ties by
//! localId (docs/fbd.md). Beremiz instead pulls blocks on demand from the out variables in file
//! order, and runs the blocks with `executionOrderId > 0` first in id order; where a body
//! carries such ids, a note lists them (`plc-deps order` shows the order plc-deps uses).
//!
//! Deliberately not here (errors naming the element): negated or edge-qualified pins, several
//! wires into one FBD pin, ENO wired on, expressions as in/out variables.

use super::black_box;
use super::block_types::{BlackBox, Ctx};
use super::pins::{
    add_target, bool_literal, konst, output_negated, pin_modifiers, pin_of, unconnected_default,
    Added,
};
use super::wiring::{graph, ElemId, Graph, Source};
use super::write_places::{self, Statement};
use super::xml::{attr, error, identifier, origin, variable_ref, ExecOrder, Note, Notes, Tc6, R};
use plc_diag::{Invalid, LoadError, Origin};
use plc_syntax::fbd::{Block, Connection, Input, Inputs, Network, OutVar, Outputs, Targets};
use plc_syntax::{FbdBody, Scalar};
use roxmltree::Node;
use std::borrow::Cow;
use std::cell::RefCell;
use std::collections::HashMap;

const FBD_TAGS: &[&str] = &[
    "block",
    "inVariable",
    "outVariable",
    "inOutVariable",
    "connector",
    "continuation",
    "jump",
    "label",
    "return",
    "comment",
];

/// Reads FBD body `node` of POU `pou`.
pub(super) fn body(
    tc6: Tc6,
    node: Node,
    pou: &str,
    ctx: &Ctx,
    notes: &mut Notes,
) -> R<FbdBody<'static>> {
    let place = format!("pou {pou}, FBD");
    let g = graph(tc6, node, &place, notes)?;
    g.only(FBD_TAGS, "FBD", &place)?;
    let mut ordered = Vec::new();
    for el in &g.elems {
        if let Some(x) = el
            .node
            .attribute("executionOrderId")
            .and_then(|x| x.trim().parse::<u32>().ok())
        {
            if x > 0 {
                ordered.push((x, el.local_id));
            }
        }
    }
    ordered.sort_unstable();
    let f = Fbd {
        g: &g,
        place,
        a: RefCell::new(Added::new(&g).with_elements(&ctx.vars)),
        ctx,
        boxes: RefCell::new(std::mem::take(&mut notes.black_boxes)),
        notes: RefCell::new(Vec::new()),
        eno_ends: RefCell::new(HashMap::new()),
    };
    let mut networks: Vec<Network<'static>> = Vec::new();
    let mut current: Vec<Block<'static>> = Vec::new();
    let mut label: Option<(String, Node)> = None;
    let mut labels = 0;
    let mut comments: Vec<String> = Vec::new();
    for (i, el) in g.elems.iter().enumerate() {
        let e = ElemId(i as u32);
        match el.tag {
            "label" => {
                let here = g.place(&f.place, e);
                let l = identifier(attr(el.node, "label", &here)?, "label", el.node, &here)?;
                if !current.is_empty() || label.is_some() {
                    let k = networks.len();
                    f.close_loops(&mut current);
                    networks.push(network(
                        pou,
                        k,
                        label.take(),
                        std::mem::take(&mut current),
                        std::mem::take(&mut comments),
                    ));
                }
                labels += 1;
                label = Some((l, el.node));
            }
            "comment" => {
                let t: String = el
                    .node
                    .descendants()
                    .filter(|d| d.is_text())
                    .filter_map(|d| d.text())
                    .collect();
                if !t.trim().is_empty() {
                    comments.push(t.trim().to_owned());
                }
            }
            "block" => current.push(f.block(e)?),
            "jump" | "return" => current.push(f.control(e)?),
            "outVariable" | "inOutVariable" => {
                if let Some(b) = f.variable_move(e)? {
                    current.push(b);
                }
            }
            _ => {}
        }
        current.append(&mut f.a.borrow_mut().blocks);
    }
    let k = networks.len();
    f.close_loops(&mut current);
    networks.push(network(pou, k, label, current, comments));
    // Each network's statements, in order (a statement is its block's or its target's).
    let statements = statement_order(&g);
    let mut owner: HashMap<Statement, usize> = HashMap::new();
    for (k, n) in networks.iter().enumerate() {
        for b in n.blocks.iter().flatten() {
            if let Ok(&id) = b.id.as_ref() {
                owner.insert(Statement::Run(id), k);
            }
            for at in write_places::target_origins(b) {
                owner.insert(Statement::Write { at, local_id: 0 }, k);
            }
        }
    }
    let mut per_network: Vec<Vec<Statement>> = vec![Vec::new(); networks.len()];
    for s in statements {
        let key = match s {
            Statement::Write { at, .. } => Statement::Write { at, local_id: 0 },
            run => run,
        };
        if let Some(&k) = owner.get(&key) {
            per_network[k].push(s);
        }
    }
    for (n, statements) in networks.iter_mut().zip(&per_network) {
        if let Ok(blocks) = &mut n.blocks {
            super::user_functions::call_pins(blocks);
            let roots = write_places::place_writes(blocks, statements, &mut f.a.borrow_mut(), ctx);
            n.order = Some(Ok(roots.into_iter().map(Ok).collect()));
        }
    }
    if labels == 0 {
        if let Some(n) = networks.first_mut() {
            n.id = Ok(Cow::Owned(pou.to_owned()));
        }
    }
    notes.black_boxes = f.boxes.take();
    notes.list.extend(f.notes.take());
    let vars = std::mem::take(&mut f.a.borrow_mut().vars);
    notes
        .ld_vars
        .extend(vars.into_iter().map(|v| (pou.to_owned(), v)));
    if !ordered.is_empty() {
        notes.exec_orders.push(ExecOrder {
            networks: networks
                .iter()
                .filter_map(|n| n.id.as_ref().ok().map(|i| i.to_string()))
                .collect(),
            origin: origin(node),
            ids: ordered,
        });
    }
    Ok(FbdBody {
        origin: origin(node),
        comment: None,
        networks,
        problem: None,
    })
}

/// Beremiz's statement order of an FBD body (PLCGenerator.ComputeProgram): the blocks, out and
/// in-out variables with an `executionOrderId` above 0 in that order, then the out and in-out
/// variables in file order, then the blocks in file order. An out variable's statement is its
/// write ([`write_places`] finds the block that holds it), a block's is its run. Beremiz
/// computes a block when a statement first reads it, which the depth-first order from these
/// roots does.
fn statement_order(g: &Graph) -> Vec<Statement> {
    let statement = |i: usize| -> Option<Statement> {
        let el = &g.elems[i];
        match el.tag {
            "block" => Some(Statement::Run(el.local_id)),
            "outVariable" | "inOutVariable" => match el.inputs.first().map(|p| p.sources.len()) {
                Some(1) => Some(Statement::Write {
                    at: origin(el.node),
                    local_id: el.local_id,
                }),
                _ => None,
            },
            _ => None,
        }
    };
    let exec_id = |i: usize| {
        g.elems[i]
            .node
            .attribute("executionOrderId")
            .and_then(|x| x.trim().parse::<u32>().ok())
            .filter(|&x| x > 0)
    };
    let mut ordered: Vec<(u32, usize)> = (0..g.elems.len())
        .filter_map(|i| exec_id(i).map(|x| (x, i)))
        .collect();
    ordered.sort_unstable();
    let mut statements: Vec<Statement> =
        ordered.iter().filter_map(|&(_, i)| statement(i)).collect();
    for tags in [&["outVariable", "inOutVariable"][..], &["block"][..]] {
        for i in 0..g.elems.len() {
            if tags.contains(&g.elems[i].tag) && exec_id(i).is_none() {
                statements.extend(statement(i));
            }
        }
    }
    statements
}

fn network(
    pou: &str,
    k: usize,
    label: Option<(String, Node)>,
    blocks: Vec<Block<'static>>,
    comments: Vec<String>,
) -> Network<'static> {
    let at = label
        .as_ref()
        .map_or(plc_diag::Origin::NONE, |(_, n)| origin(*n));
    Network {
        origin: at,
        id: Ok(Cow::Owned(format!("{pou}.N{}", k + 1))),
        label: label.map(|(l, _)| Ok(Cow::Owned(l))),
        comment: (!comments.is_empty()).then(|| Ok(Cow::Owned(comments.join("\n")))),
        blocks: Ok(blocks),
        order: None,
        problem: None,
    }
}

struct Fbd<'g, 'a, 'i> {
    g: &'g Graph<'a, 'i>,
    place: String,
    /// Blocks the reader adds (NOT of a negated pin, edge detectors), for the current network.
    a: RefCell<Added>,
    /// What blocks may call, and the types of the names the body sees.
    ctx: &'g Ctx,
    /// The project's black boxes so far ([`black_box`]).
    boxes: RefCell<Vec<BlackBox>>,
    notes: RefCell<Vec<Note>>,
    /// For a block, the block at the end of its chain of ENO → EN wires ([`Fbd::eno`]).
    eno_ends: RefCell<HashMap<ElemId, ElemId>>,
}

impl Fbd<'_, '_, '_> {
    fn at(&self, e: ElemId) -> String {
        self.g.place(&self.place, e)
    }

    fn new_block(&self, e: ElemId, op: &str) -> Block<'static> {
        let el = self.g.get(e);
        Block {
            origin: origin(el.node),
            id: Ok(el.local_id),
            op: Ok(Cow::Owned(op.to_owned())),
            inputs: None,
            outputs: None,
            instance: None,
            label: None,
            cond: None,
            en: false,
            after: None,
            comment: None,
            problem: None,
        }
    }

    /// The field inputs `pin.f` ← `var.f` when input `pin` of function block type `ty` is a
    /// structure (the type declares its fields `pin.f`, not `pin`) and `input` reads variable
    /// `var` whole; `None` otherwise.
    fn whole_structure(
        &self,
        ty: &str,
        pin: &str,
        input: &Input<'static>,
    ) -> Option<Vec<(Cow<'static, str>, Input<'static>)>> {
        let Connection::Variable(v) = &input.from else {
            return None;
        };
        // A function block's inputs, or a function's (a user function is a black box whose
        // pins are its declared inputs, a structure one per field).
        let declared = self
            .ctx
            .fb_inputs
            .get(ty)
            .or_else(|| self.ctx.functions.get(ty).map(|s| &s.inputs))?;
        if declared.iter().any(|(n, _)| n == pin) {
            return None;
        }
        let prefix = format!("{pin}.");
        let fields: Vec<(Cow<'static, str>, Input<'static>)> = declared
            .iter()
            .filter_map(|(n, _)| n.strip_prefix(&prefix).map(|f| (n, f)))
            .map(|(n, f)| {
                let from = Connection::Variable(Cow::Owned(format!("{v}.{f}")));
                let field = Input {
                    origin: input.origin,
                    from,
                };
                (Cow::Owned(n.clone()), field)
            })
            .collect();
        (!fields.is_empty()).then_some(fields)
    }

    /// Input `pin` of block `ty` under the name the model knows it by: IEC names are
    /// case-insensitive, and CODESYS writes an operator's pins `In1`, `In2` (MUX `K`, `In0`):
    /// a declared input of a function block or function of the project as declared, a pin of
    /// a standard function or function block in upper case; others (black boxes) as written.
    fn pin_name(&self, ty: &str, pin: &str) -> String {
        let declared = self
            .ctx
            .fb_inputs
            .get(ty)
            .or_else(|| self.ctx.functions.get(ty).map(|s| &s.inputs));
        if let Some(d) = declared {
            return d
                .iter()
                .find(|(n, _)| n.eq_ignore_ascii_case(pin))
                .map_or_else(|| pin.to_owned(), |(n, _)| n.clone());
        }
        if let Some(op) = plc_fbd::OpKind::parse(ty) {
            let upper = pin.to_ascii_uppercase();
            // A one-input operator's `In1` is its IN (NOT, ABS, the conversions).
            let pins = op.input_pins(0);
            if upper == "IN1" && pins.iter().any(|p| p == "IN") && !pins.iter().any(|p| p == "IN1")
            {
                return "IN".to_owned();
            }
            return upper;
        }
        if black_box::is_standard_fb(ty) {
            return pin.to_ascii_uppercase();
        }
        pin.to_owned()
    }

    fn block(&self, e: ElemId) -> R<Block<'static>> {
        let el = self.g.get(e);
        let here = self.at(e);
        let mut ty = attr(el.node, "typeName", &here)?;
        let declared_type;
        let mut b = self.new_block(e, ty);
        if let Some(inst) = el.node.attribute("instanceName") {
            b.instance = Some(Ok(Cow::Owned(identifier(
                inst, "instance", el.node, &here,
            )?)));
            // Beremiz calls the instance by name, so the instance's type decides what runs.
            if let Some(declared) = self.ctx.fb_type_of(inst).filter(|d| d != ty) {
                self.notes.borrow_mut().push(Note {
                    origin: origin(el.node),
                    message: format!("{here}: the block is a {ty} but its instance `{inst}` is declared {declared}; it is read as a call of {declared} (Beremiz calls the instance by name)"),
                });
                declared_type = declared;
                ty = &declared_type;
                b.op = Ok(Cow::Owned(ty.to_owned()));
            }
        }
        let mut inputs = Vec::new();
        for pin in &el.inputs {
            let canon = self.pin_name(ty, pin.name.unwrap_or(""));
            let name = canon.as_str();
            let (negated, edge) = pin_modifiers(pin.node, ty, name, el.local_id, &here)?;
            let init = el
                .node
                .attribute("instanceName")
                .and_then(|i| self.ctx.init_of(i, name));
            let mut input = match pin.sources.as_slice() {
                // An unconnected input keeps the value the instance's declaration gives it
                // (IEC 61131-3 6.5.1.4: `T0 : TON := (PT := T#1s)`).
                [] if init.is_some() => {
                    let (v, at) = init.unwrap_or((Scalar::Bool(false), origin(pin.node)));
                    Input {
                        origin: at,
                        from: Connection::Constant(v),
                    }
                }
                // An unconnected BOOL input of a standard function block keeps its initial
                // value FALSE (nothing in the body sets it, IEC 61131-3 2.5.2.1).
                [] if black_box::is_standard_fb(ty)
                    && self.ctx.input_type(ty, name).as_deref() == Some("BOOL") =>
                {
                    konst(false, origin(pin.node))
                }
                [] => match unconnected_default(ty, name, origin(pin.node)) {
                    Some((c, text)) => {
                        self.notes.borrow_mut().push(Note {
                            origin: origin(pin.node),
                            message: format!("{here}: input {name} of {ty} (localId {}) is not connected: it takes its type's initial value {text} (IEC 61131-3 2.5.2.1)", el.local_id),
                        });
                        c
                    }
                    None => continue,
                },
                [s] => self.input(e, s)?,
                _ => {
                    return Err(error(
                        origin(pin.node),
                        &here,
                        format!("input {name} of {ty} (localId {}) has {} connections; an FBD pin takes one", el.local_id, pin.sources.len()),
                    ))
                }
            };
            let at = origin(pin.node);
            let counter_edge = matches!(ty, "CTU" | "CTD" | "CTUD") && matches!(name, "CU" | "CD");
            let mut a = self.a.borrow_mut();
            match edge {
                Some(edge) if !(counter_edge && edge == "rising") => {
                    input = a.trigger(edge, input, el.local_id, at)
                }
                _ => {}
            }
            if negated {
                input = a.not(input, at);
            }
            drop(a);
            if let Connection::Variable(v) = &input.from {
                if let Some(k) = super::library::library_constant(ty, name, v) {
                    input.from = Connection::Constant(Scalar::Number(k.into()));
                }
            }
            input = bool_literal(self.ctx, ty, name, input);
            if name == "EN" {
                b.cond = Some(input);
                b.en = true;
            } else if let Some(fields) = self.whole_structure(ty, name, &input) {
                // A structure passed whole into a function block's structure input: each field
                // into its field (the model holds a structure as one variable per field).
                inputs.extend(fields);
            } else {
                inputs.push((Cow::Owned(name.to_owned()), input));
            }
        }
        // The inputs the instance's declaration gives a value and the block does not list.
        if let Some(inst) = el.node.attribute("instanceName") {
            for (pin, v, at) in self.ctx.init_inputs(inst, ty) {
                if !el
                    .inputs
                    .iter()
                    .any(|p| p.name.is_some_and(|n| n.eq_ignore_ascii_case(&pin)))
                {
                    let input = Input {
                        origin: at,
                        from: Connection::Constant(v),
                    };
                    let input = bool_literal(self.ctx, ty, &pin, input);
                    inputs.push((Cow::Owned(pin), input));
                }
            }
        }
        positional_pins(ty, &mut inputs);
        b.inputs = Some(Ok(Inputs::Named(inputs)));
        let t = black_box::Typer {
            ctx: self.ctx,
            g: self.g,
        };
        self.a
            .borrow_mut()
            .compare(&mut b, el.inputs.len(), &|i: &Input| t.input(i, 0));
        if !black_box::is_known(self.ctx, ty) || black_box::mixed_arithmetic(&t, ty, &b) {
            let mut boxes = self.boxes.borrow_mut();
            if let Some((inst, bt)) = black_box::rewrite(&t, e, &mut b, &mut boxes, &here)? {
                self.a.borrow_mut().declare(&inst, &bt, b.origin);
            }
        }
        for (pin, pnode) in &el.outputs {
            let targets = self.targets(e, pin, el.outputs.first().map(|o| o.0) == Some(*pin))?;
            let negated = matches!(pnode.attribute("negated"), Some("true" | "1"));
            let targets = if negated && !targets.is_empty() {
                // The variables a negated output writes get NOT of it.
                let at = origin(*pnode);
                let arc = Input {
                    origin: at,
                    from: Connection::Arc {
                        block: el.local_id,
                        pin: Some(Ok(Cow::Owned(pin_of(pin).to_owned()))),
                    },
                };
                let mut a = self.a.borrow_mut();
                a.not(arc, at);
                if let Some(n) = a.blocks.last_mut() {
                    n.outputs = Some(Ok(Outputs::Named(vec![(
                        Cow::Borrowed("OUT"),
                        Ok(Targets::Many(targets.into_iter().map(Ok).collect())),
                    )])));
                }
                Vec::new()
            } else {
                targets
            };
            if *pin == "ENO" && !targets.is_empty() {
                // ENO is EN (IEC 61131-3 2.5.1.2: TRUE when the block ran without error).
                let en = self.eno(e, origin(*pnode))?;
                // Beremiz writes an out variable fed by a block with EN only under
                // `IF <ENO> THEN` (PLCGenerator.GetUsedEno): a MOVE gated by the same EN.
                let mut a = self.a.borrow_mut();
                a.add_on("MOVE", None, Inputs::List(vec![en.clone()]), origin(*pnode));
                if let Some(m) = a.blocks.last_mut() {
                    m.cond = Some(en);
                    m.en = true;
                    for t in targets {
                        add_target(m, "OUT".to_owned(), t);
                    }
                }
                continue;
            }
            for t in targets {
                add_target(&mut b, pin_of(pin).to_owned(), t);
            }
        }
        Ok(b)
    }

    /// The out and in-out variables output `pin` of block `e` writes (`first`: the block's first
    /// output, which a connection without `formalParameter` means).
    fn targets(&self, e: ElemId, pin: &str, first: bool) -> R<Vec<OutVar<'static>>> {
        let mut out = Vec::new();
        for &(c, _, p) in &self.g.consumers[e.0 as usize] {
            let cel = self.g.get(c);
            let this = match p {
                Some(p) => p == pin,
                None => first,
            };
            if this && matches!(cel.tag, "outVariable" | "inOutVariable") {
                out.push(OutVar {
                    origin: origin(cel.node),
                    name: Cow::Owned(self.var_name(c)?),
                });
            }
        }
        Ok(out)
    }

    fn var_name(&self, e: ElemId) -> R<String> {
        let el = self.g.get(e);
        let text = el
            .node
            .children()
            .find(|c| c.is_element() && c.tag_name().name() == "expression")
            .and_then(|c| c.text())
            .ok_or_else(|| {
                error(
                    origin(el.node),
                    &self.at(e),
                    format!("the {} has no expression", el.tag),
                )
            })?;
        variable_ref(text, el.node, &self.at(e))
    }

    /// Cuts the loops of arcs among `blocks` as Beremiz closes them ([`super::fbd_loops`]).
    fn close_loops(&self, blocks: &mut [Block<'static>]) {
        let t = black_box::Typer {
            ctx: self.ctx,
            g: self.g,
        };
        let ty = |id: u32, pin: Option<&str>| {
            let e = self.g.elems.iter().position(|el| el.local_id == id)?;
            t.output(ElemId(e as u32), pin, 0)
        };
        let notes = super::fbd_loops::cut(blocks, &mut self.a.borrow_mut(), &ty, &self.place);
        self.notes.borrow_mut().extend(notes);
    }

    /// The ENO of block `e`: what feeds its EN, TRUE without one. An EN fed by another block's
    /// ENO is that block's ENO: the chain is followed without recursion (a long chain of
    /// ENO → EN wires is a loop, not a deep call), each block's end of chain is remembered
    /// (so n blocks cost n steps in all), and a chain that comes back to a block of it is a
    /// cycle of arcs (E0409) naming the blocks' localIds.
    fn eno(&self, e: ElemId, at: Origin) -> R<Input<'static>> {
        let en_source = |b: ElemId| {
            self.g
                .get(b)
                .inputs
                .iter()
                .find(|p| p.name == Some("EN"))
                .and_then(|p| match p.sources.as_slice() {
                    [s] => Some(s),
                    _ => None,
                })
        };
        let enos = |s: &Source| self.g.get(s.elem).tag == "block" && s.pin == Some("ENO");
        let mut chain = vec![e];
        let mut on_chain = std::collections::HashSet::from([e]);
        let mut ends = self.eno_ends.borrow_mut();
        let end = loop {
            let cur = *chain.last().expect("starts with e");
            if let Some(&end) = ends.get(&cur) {
                break end;
            }
            match en_source(cur) {
                Some(s) if enos(s) => {
                    if !on_chain.insert(s.elem) {
                        let from = chain.iter().position(|&b| b == s.elem).expect("on it");
                        let mut ids: Vec<String> = chain[from..]
                            .iter()
                            .map(|&b| self.g.get(b).local_id.to_string())
                            .collect();
                        ids.reverse();
                        ids.push(ids[0].clone());
                        return Err(LoadError::invalid(
                            None,
                            &self.at(cur),
                            Invalid::Cycle {
                                blocks: ids.join(" → "),
                            },
                        )
                        .at(s.origin)
                        .with_hint("each block's EN is wired to the ENO of the block before it"));
                    }
                    chain.push(s.elem);
                }
                _ => break cur,
            }
        };
        for &b in &chain {
            ends.insert(b, end);
        }
        drop(ends);
        match en_source(end) {
            Some(s) => self.input(end, s),
            None => Ok(konst(true, at)),
        }
    }

    /// What source `s` gives to an input of block `consumer`.
    fn input(&self, consumer: ElemId, s: &Source) -> R<Input<'static>> {
        let src = self.g.get(s.elem);
        match src.tag {
            "block" if s.pin == Some("ENO") => self.eno(s.elem, s.origin),
            "block" => {
                let arc = Input {
                    origin: s.origin,
                    from: Connection::Arc {
                        block: src.local_id,
                        pin: s.pin.map(|p| Ok(Cow::Owned(pin_of(p).to_owned()))),
                    },
                };
                if output_negated(&src.outputs, s.pin) {
                    return Ok(self.a.borrow_mut().not(arc, s.origin));
                }
                Ok(arc)
            }
            "inVariable" | "inOutVariable" => super::expression::block_input(
                &mut self.a.borrow_mut(),
                src.node,
                &self.at(s.elem),
                s.origin,
            ),
            other => Err(error(
                s.origin,
                &self.at(consumer),
                format!(
                    "a {other} (localId {}) cannot feed an input in FBD",
                    src.local_id
                ),
            )),
        }
    }

    /// JMP and RET blocks.
    fn control(&self, e: ElemId) -> R<Block<'static>> {
        let el = self.g.get(e);
        let here = self.at(e);
        let mut b = self.new_block(e, if el.tag == "jump" { "JMP" } else { "RET" });
        if el.tag == "jump" {
            let l = identifier(attr(el.node, "label", &here)?, "label", el.node, &here)?;
            b.label = Some(Ok(Cow::Owned(l)));
        }
        match el.inputs.first().map(|p| p.sources.as_slice()) {
            Some([s]) => b.cond = Some(self.input(e, s)?),
            Some([]) | None => {}
            Some(more) => {
                return Err(error(
                    origin(el.node),
                    &here,
                    format!(
                        "the {} has {} connections; it takes one",
                        el.tag,
                        more.len()
                    ),
                ))
            }
        }
        Ok(b)
    }

    /// An out or in-out variable fed directly by a variable: a MOVE block (a variable fed by a
    /// block is one of that block's outputs, `None` here).
    fn variable_move(&self, e: ElemId) -> R<Option<Block<'static>>> {
        let el = self.g.get(e);
        let here = self.at(e);
        let sources = el
            .inputs
            .first()
            .map(|p| p.sources.as_slice())
            .unwrap_or(&[]);
        match sources {
            [] if el.tag == "inOutVariable" => Ok(None),
            [] => Err(error(
                origin(el.node),
                &here,
                format!("outVariable localId {} is not connected", el.local_id),
            )),
            [s] if self.g.get(s.elem).tag == "block" => Ok(None),
            [s] => {
                let mut b = self.new_block(e, "MOVE");
                b.inputs = Some(Ok(Inputs::List(vec![self.input(e, s)?])));
                b.outputs = Some(Ok(Outputs::First(OutVar {
                    origin: origin(el.node),
                    name: Cow::Owned(self.var_name(e)?),
                })));
                Ok(Some(b))
            }
            more => Err(error(
                origin(el.node),
                &here,
                format!(
                    "{} localId {} has {} connections; it takes one",
                    el.tag,
                    el.local_id,
                    more.len()
                ),
            )),
        }
    }
}

/// CODESYS names the inputs of the standard operators by position, `In1`, `In2`, … (its own
/// operator boxes): the standard names in the standard's order (IEC 61131-3 2.5.1.5: MUX is
/// `K, IN0, IN1, …`, SEL `G, IN0, IN1`, LIMIT `MN, IN, MX`, the shifts `IN, N`, one-input
/// functions `IN`). Applied only when every data input is so named; `IN1`, `IN2` of the
/// extensible ops (ADD, AND, …) are their own names already.
fn positional_pins(op: &str, inputs: &mut [(Cow<'static, str>, Input<'static>)]) {
    let index = |n: &str| -> Option<usize> {
        let u = n.to_ascii_uppercase();
        u.strip_prefix("IN")?
            .parse::<usize>()
            .ok()
            .filter(|&k| k >= 1)
    };
    if inputs.is_empty() || !inputs.iter().all(|(n, _)| index(n).is_some()) {
        return;
    }
    let fixed: &[&str] = match op.to_ascii_uppercase().as_str() {
        "SEL" => &["G", "IN0", "IN1"],
        "LIMIT" => &["MN", "IN", "MX"],
        "SHL" | "SHR" | "ROL" | "ROR" => &["IN", "N"],
        "MUX" => &[],
        "NOT" | "MOVE" | "ABS" | "SQRT" | "LN" | "LOG" | "EXP" | "SIN" | "COS" | "TAN" | "ASIN"
        | "ACOS" | "ATAN" | "TRUNC" => &["IN"],
        u if u.contains("_TO_") => &["IN"],
        _ => return,
    };
    let mut names = Vec::with_capacity(inputs.len());
    for (n, _) in inputs.iter() {
        let k = index(n).expect("checked above");
        names.push(if op.eq_ignore_ascii_case("MUX") {
            if k == 1 {
                "K".to_owned()
            } else {
                format!("IN{}", k - 2)
            }
        } else {
            match fixed.get(k - 1) {
                Some(s) => (*s).to_owned(),
                None => return,
            }
        });
    }
    for ((n, _), name) in inputs.iter_mut().zip(names) {
        *n = Cow::Owned(name);
    }
}
