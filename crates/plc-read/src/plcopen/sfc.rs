//! SFC bodies (TC6 `SFC`, IEC 61131-3 3rd ed. 6.7) read as the chart Beremiz's generator makes
//! of them ([`Chart`]): its steps, transitions and actions in the order of the IEC textual SFC
//! that `PLCGenerator.py` writes (`GenerateSFCStep`, `GenerateSFCTransition`, `GenerateSFCJump`,
//! `GenerateSFCStepActions`, then `ComputeSFCStep` from each initial step), because that order
//! is the order matiec evaluates transitions, associations and actions in.
//!
//! Read: `step` (initial or not), `transition` (its `priority`, its condition: `inline` ST, a
//! `reference` to one of the POU's `transitions` with an ST body `:= expr;` or an LD/FBD body
//! whose coil or outVariable named after it is fed by contacts, variables and NOT/AND/OR/XOR
//! functions, or a `connection` to such elements of the SFC body), `selectionDivergence`,
//! `selectionConvergence`, `simultaneousDivergence`, `simultaneousConvergence`, `jumpStep`,
//! `actionBlock` (each `action` with its qualifier, duration and indicator; a `reference` to one
//! of the POU's `actions` or to a variable, or an `inline` ST body, named `STEP_INLINEn` as
//! Beremiz names it). A transition's condition that goes through a function block instance
//! (Beremiz computes those in an extra action, `COMPUTE_FUNCTION_BLOCKS`), a `macroStep`, an
//! IL condition, and an action body in another language than ST or LD are [`Chart::refused`]
//! with their place, never skipped.
//!
//! Invariant: only what Beremiz's generator writes exists: a step that no initial step leads to
//! is not in the chart (Beremiz leaves it out of the generated program, so matiec never runs
//! it); an action no step uses likewise.
//! Deliberately not here: the scan semantics (the lowering, [`super::sfc_lower`]).

use super::xml::{origin, Tc6};
use plc_diag::Origin;
use roxmltree::Node;
use std::collections::HashMap;

/// A transition's condition or an action's body, as text to parse and where it is.
#[derive(Clone)]
pub(super) enum Code<'a, 'i> {
    /// An ST expression (an inline condition, or one built from LD/FBD elements).
    Expr { text: String, node: Node<'a, 'i> },
    /// ST statements in the text node `node` (an action's body).
    Statements { node: Node<'a, 'i> },
    /// An LD body (an action's).
    Ld { node: Node<'a, 'i> },
    /// ST statements made here (Beremiz's COMPUTE_FUNCTION_BLOCKS action), located at `node`.
    Text { text: String, node: Node<'a, 'i> },
}

/// One action association of a step (`A(N)`, `A(L, T#2s)`).
pub(super) struct Assoc {
    pub action: String,
    pub qualifier: String,
    pub duration: Option<String>,
    pub origin: Origin,
}

pub(super) struct Step {
    pub name: String,
    pub initial: bool,
    pub origin: Origin,
    pub assocs: Vec<Assoc>,
}

pub(super) struct Transition<'a, 'i> {
    /// The transition in rung ids: `T<localId>`, `T<localId>.NAME` for a named transition.
    pub unit: String,
    pub origin: Origin,
    pub priority: Option<i64>,
    pub from: Vec<String>,
    pub to: Vec<String>,
    pub cond: Code<'a, 'i>,
}

pub(super) struct Action<'a, 'i> {
    pub name: String,
    pub origin: Origin,
    pub body: Code<'a, 'i>,
}

/// The chart in the order of Beremiz's textual SFC.
#[derive(Default)]
pub(super) struct Chart<'a, 'i> {
    pub steps: Vec<Step>,
    pub transitions: Vec<Transition<'a, 'i>>,
    pub actions: Vec<Action<'a, 'i>>,
    /// The first thing that cannot be executed, and where it is.
    pub refused: Option<(Origin, String)>,
    /// The BOOL temporaries of COMPUTE_FUNCTION_BLOCKS (Beremiz's `_TMP_…_OUT`).
    pub temps: Vec<String>,
}

struct StepInfo {
    initial: bool,
    origin: Origin,
    transitions: Vec<usize>,
    assocs: Vec<Assoc>,
}

struct TrInfo<'a, 'i> {
    id: String,
    unit: String,
    origin: Origin,
    priority: Option<i64>,
    from: Vec<String>,
    to: Vec<String>,
    cond: Option<Code<'a, 'i>>,
}

/// Beremiz's generation state (`SFCNetworks`, `InitialSteps`), keyed as it keys them.
struct Gen<'a, 'i> {
    tc6: Tc6,
    pou: Node<'a, 'i>,
    by_id: HashMap<&'a str, Node<'a, 'i>>,
    steps: HashMap<String, StepInfo>,
    step_order: Vec<String>,
    trs: Vec<TrInfo<'a, 'i>>,
    tr_index: HashMap<String, usize>,
    actions: HashMap<String, (Origin, Code<'a, 'i>)>,
    initial: Vec<String>,
    inline_count: usize,
    refused: Option<(Origin, String)>,
    /// Beremiz's `SFCComputedBlocks`: the statements of the blocks transition conditions go
    /// through, the blocks done (by file offset), and their temporaries.
    compute: Vec<String>,
    computed: std::collections::HashSet<usize>,
    temps: Vec<String>,
}

/// Reads SFC body `sfc` of POU `pou` into its chart.
pub(super) fn chart<'a, 'i>(tc6: Tc6, pou: Node<'a, 'i>, sfc: Node<'a, 'i>) -> Chart<'a, 'i> {
    let mut g = Gen {
        tc6,
        pou,
        by_id: HashMap::new(),
        steps: HashMap::new(),
        step_order: Vec::new(),
        trs: Vec::new(),
        tr_index: HashMap::new(),
        actions: HashMap::new(),
        initial: Vec::new(),
        inline_count: 0,
        refused: None,
        compute: Vec::new(),
        computed: std::collections::HashSet::new(),
        temps: Vec::new(),
    };
    for n in tc6.elements(sfc) {
        if let Some(id) = n.attribute("localId") {
            g.by_id.insert(id, n);
        }
    }
    for n in tc6.elements(sfc) {
        match n.tag_name().name() {
            "step" => g.step(n),
            "actionBlock" => g.step_actions(n),
            "transition" => {
                g.transition(n);
            }
            "jumpStep" => g.jump(n),
            "macroStep" => g.refuse(n, "a macro step (`macroStep`)"),
            _ => {}
        }
    }
    if g.initial.is_empty() && g.refused.is_none() {
        g.refused = Some((origin(sfc), "an SFC body without an initial step".into()));
    }
    // GenerateSFCBody: the blocks the conditions need, an action set by the first initial step.
    if let (Some(first), false) = (g.initial.first().cloned(), g.compute.is_empty()) {
        let name = "COMPUTE_FUNCTION_BLOCKS".to_owned();
        let text = g.compute.join("\n");
        g.actions
            .insert(name.clone(), (origin(sfc), Code::Text { text, node: sfc }));
        if let Some(s) = g.steps.get_mut(&first) {
            s.assocs.push(Assoc {
                action: name,
                qualifier: "S".into(),
                duration: None,
                origin: origin(sfc),
            });
        }
    }
    let mut c = Chart::default();
    let mut done_steps = std::collections::HashSet::new();
    let mut done_trs = std::collections::HashSet::new();
    for s in g.initial.clone() {
        g.compute_step(&s, &mut c, &mut done_steps, &mut done_trs);
    }
    c.refused = g.refused;
    c.temps = g.temps;
    c
}

/// The `refLocalId`s of the connections of `cpi` when it has exactly one (Beremiz's rule).
fn single_ref<'a>(cpi: Option<Node<'a, '_>>) -> Option<&'a str> {
    let cpi = cpi?;
    let conns: Vec<_> = cpi
        .children()
        .filter(|c| c.is_element() && c.tag_name().name() == "connection")
        .collect();
    match conns.as_slice() {
        [c] => c.attribute("refLocalId"),
        _ => None,
    }
}

impl<'a, 'i> Gen<'a, 'i> {
    fn refuse(&mut self, n: Node, what: impl Into<String>) {
        if self.refused.is_none() {
            self.refused = Some((origin(n), what.into()));
        }
    }

    fn node(&self, id: Option<&str>) -> Option<Node<'a, 'i>> {
        id.and_then(|i| self.by_id.get(i).copied())
    }

    fn input(&self, n: Node<'a, 'i>) -> Option<Node<'a, 'i>> {
        self.node(single_ref(self.tc6.child(n, "connectionPointIn")))
    }

    /// `ExtractConvergenceInputs`: what feeds each input of a convergence.
    fn convergence_inputs(&self, n: Node<'a, 'i>) -> Vec<Node<'a, 'i>> {
        self.tc6
            .children(n, "connectionPointIn")
            .filter_map(|c| self.node(single_ref(Some(c))))
            .collect()
    }

    /// The transitions that lead into a step or jump fed by `n` (Beremiz's cases).
    fn feeding_transitions(&self, n: Node<'a, 'i>) -> Vec<Node<'a, 'i>> {
        let Some(inst) = self.input(n) else {
            return Vec::new();
        };
        match inst.tag_name().name() {
            "transition" => vec![inst],
            "selectionConvergence" => self.convergence_inputs(inst),
            "simultaneousDivergence" => match self.input(inst) {
                Some(t) if t.tag_name().name() == "transition" => vec![t],
                Some(c) if c.tag_name().name() == "selectionConvergence" => {
                    self.convergence_inputs(c)
                }
                _ => Vec::new(),
            },
            _ => Vec::new(),
        }
    }

    /// `GenerateSFCStep`.
    fn step(&mut self, n: Node<'a, 'i>) {
        let name = n.attribute("name").unwrap_or("").to_owned();
        if self.steps.contains_key(&name) {
            return;
        }
        let initial = n.attribute("initialStep") == Some("true");
        if initial {
            self.initial.push(name.clone());
        }
        self.steps.insert(
            name.clone(),
            StepInfo {
                initial,
                origin: origin(n),
                transitions: Vec::new(),
                assocs: Vec::new(),
            },
        );
        self.step_order.push(name.clone());
        for t in self.feeding_transitions(n) {
            if let Some(k) = self.transition(t) {
                self.trs[k].to.push(name.clone());
            }
        }
    }

    /// `GenerateSFCJump`.
    fn jump(&mut self, n: Node<'a, 'i>) {
        let target = n.attribute("targetName").unwrap_or("").to_owned();
        let exists = self
            .by_id
            .values()
            .any(|s| s.tag_name().name() == "step" && s.attribute("name") == Some(&target));
        if !exists {
            self.refuse(n, format!("a jump to `{target}`, which is not a step"));
            return;
        }
        for t in self.feeding_transitions(n) {
            if let Some(k) = self.transition(t) {
                self.trs[k].to.push(target.clone());
            }
        }
    }

    /// `GenerateSFCStepActions`.
    fn step_actions(&mut self, n: Node<'a, 'i>) {
        let Some(step) = self.input(n) else {
            return;
        };
        if step.tag_name().name() != "step" {
            return;
        }
        self.step(step);
        let step_name = step.attribute("name").unwrap_or("").to_owned();
        let tc6 = self.tc6;
        for a in tc6.children(n, "action") {
            let qualifier = a.attribute("qualifier").unwrap_or("N").to_owned();
            let duration = a
                .attribute("duration")
                .filter(|d| !d.trim().is_empty())
                .map(str::to_owned);
            let action = if let Some(r) = tc6.child(a, "reference") {
                let name = r.attribute("name").unwrap_or("").to_owned();
                self.action(&name);
                name
            } else if let Some(i) = tc6.child(a, "inline") {
                self.inline_count += 1;
                let name = format!("{}_INLINE{}", step_name.to_uppercase(), self.inline_count);
                match tc6.child(i, "ST").and_then(text_node) {
                    Some(t) => {
                        self.actions
                            .insert(name.clone(), (origin(a), Code::Statements { node: t }));
                    }
                    None => self.refuse(a, "an inline action whose body is not ST"),
                }
                name
            } else {
                self.refuse(a, "an action without a reference or an inline body");
                continue;
            };
            if let Some(s) = self.steps.get_mut(&step_name) {
                s.assocs.push(Assoc {
                    action,
                    qualifier,
                    duration,
                    origin: origin(a),
                });
            }
        }
    }

    /// `GenerateSFCAction`: the POU's action `name`, when it has one.
    fn action(&mut self, name: &str) {
        if self.actions.contains_key(name) {
            return;
        }
        let tc6 = self.tc6;
        let Some(def) = tc6.child(self.pou, "actions").and_then(|acts| {
            tc6.children(acts, "action")
                .find(|a| a.attribute("name") == Some(name))
        }) else {
            return;
        };
        let body = tc6.child(def, "body").and_then(|b| {
            tc6.elements(b)
                .find(|e| !matches!(e.tag_name().name(), "documentation" | "addData"))
        });
        let code = match body {
            Some(b) if b.tag_name().name() == "ST" => match text_node(b) {
                Some(t) => Code::Statements { node: t },
                None => Code::Expr {
                    text: String::new(),
                    node: b,
                },
            },
            Some(b) if b.tag_name().name() == "LD" => Code::Ld { node: b },
            Some(b) => {
                self.refuse(
                    b,
                    format!("the {} body of action `{name}`", b.tag_name().name()),
                );
                return;
            }
            None => {
                self.refuse(def, format!("action `{name}` without a body"));
                return;
            }
        };
        self.actions.insert(name.to_owned(), (origin(def), code));
    }

    /// `GenerateSFCTransition`: its index.
    fn transition(&mut self, n: Node<'a, 'i>) -> Option<usize> {
        if n.tag_name().name() != "transition" {
            self.refuse(n, format!("a `{}` where a transition is expected (Beremiz's generator reads only transitions into a step, a jump or a selectionConvergence)", n.tag_name().name()));
            return None;
        }
        let id = n.attribute("localId").unwrap_or("").to_owned();
        if let Some(&k) = self.tr_index.get(&id) {
            return Some(k);
        }
        let mut from = Vec::new();
        if let Some(inst) = self.input(n) {
            match inst.tag_name().name() {
                "step" => from.push(inst),
                "selectionDivergence" => match self.input(inst) {
                    Some(s) if s.tag_name().name() == "step" => from.push(s),
                    Some(c) if c.tag_name().name() == "simultaneousConvergence" => {
                        from.extend(self.convergence_inputs(c))
                    }
                    _ => {}
                },
                "simultaneousConvergence" => from.extend(self.convergence_inputs(inst)),
                _ => {}
            }
        }
        let priority = n.attribute("priority").and_then(|p| p.trim().parse().ok());
        let k = self.trs.len();
        self.tr_index.insert(id.clone(), k);
        self.trs.push(TrInfo {
            unit: format!("T{id}"),
            id,
            origin: origin(n),
            priority,
            from: Vec::new(),
            to: Vec::new(),
            cond: None,
        });
        let cond = self.condition(n, k);
        self.trs[k].cond = cond;
        for s in from {
            if s.tag_name().name() != "step" {
                continue;
            }
            self.step(s);
            let name = s.attribute("name").unwrap_or("").to_owned();
            if let Some(info) = self.steps.get_mut(&name) {
                self.trs[k].from.push(name);
                info.transitions.push(k);
            }
        }
        Some(k)
    }

    fn condition(&mut self, n: Node<'a, 'i>, k: usize) -> Option<Code<'a, 'i>> {
        let tc6 = self.tc6;
        let Some(c) = tc6.child(n, "condition") else {
            self.refuse(
                n,
                format!(
                    "a transition without a condition ({} {:?})",
                    n.tag_name().name(),
                    n.attribute("localId")
                ),
            );
            return None;
        };
        if let Some(i) = tc6.child(c, "inline") {
            return match tc6.child(i, "ST").and_then(text_node) {
                Some(t) => Some(Code::Expr {
                    text: t.text().unwrap_or("").to_owned(),
                    node: t,
                }),
                None => {
                    self.refuse(i, "an inline transition condition that is not ST");
                    None
                }
            };
        }
        if let Some(r) = tc6.child(c, "reference") {
            let name = r.attribute("name").unwrap_or("").to_owned();
            self.trs[k].unit = format!("{}.{name}", self.trs[k].unit);
            return self.named_transition(r, &name);
        }
        // The old schema (tc6.xsd) puts the connection right in the condition.
        let direct = tc6.child(c, "connection").map(|_| c);
        if let Some(cpi) = tc6.child(c, "connectionPointIn").or(direct) {
            let by_id = self.by_id.clone();
            return match self.expression(&by_id, cpi) {
                Ok(text) => Some(Code::Expr { text, node: n }),
                Err((at, what)) => {
                    self.refuse(at, what);
                    None
                }
            };
        }
        self.refuse(
            c,
            "a transition condition that is neither inline, a reference nor a connection",
        );
        None
    }

    /// The condition of the POU's transition `name` (Beremiz: an ST body pasted after the
    /// TRANSITION line, so written `:= expr;`; LD/FBD: its coil or outVariable `name`'s input).
    fn named_transition(&mut self, r: Node<'a, 'i>, name: &str) -> Option<Code<'a, 'i>> {
        let tc6 = self.tc6;
        let Some(def) = tc6.child(self.pou, "transitions").and_then(|ts| {
            tc6.children(ts, "transition")
                .find(|t| t.attribute("name") == Some(name))
        }) else {
            self.refuse(
                r,
                format!("a reference to transition `{name}`, which the POU does not have"),
            );
            return None;
        };
        let Some(body) = tc6.child(def, "body").and_then(|b| {
            tc6.elements(b)
                .find(|e| !matches!(e.tag_name().name(), "documentation" | "addData"))
        }) else {
            self.refuse(def, format!("transition `{name}` without a body"));
            return None;
        };
        match body.tag_name().name() {
            "ST" => {
                let t = text_node(body)?;
                let text = t.text().unwrap_or("");
                let trimmed = text.trim_start();
                match trimmed.strip_prefix(":=") {
                    Some(_) => Some(Code::Expr {
                        text: text.replacen(":=", "  ", 1),
                        node: t,
                    }),
                    None => {
                        self.refuse(t, format!("the ST body of transition `{name}` is not `:= expression;` (what Beremiz's generator passes to matiec)"));
                        None
                    }
                }
            }
            "LD" | "FBD" => {
                let mut by_id = HashMap::new();
                for n in tc6.elements(body) {
                    if let Some(id) = n.attribute("localId") {
                        by_id.insert(id, n);
                    }
                }
                let out = tc6.elements(body).find(|e| {
                    (e.tag_name().name() == "outVariable"
                        && tc6
                            .child(*e, "expression")
                            .and_then(|x| x.text())
                            .map(str::trim)
                            == Some(name))
                        || (e.tag_name().name() == "coil"
                            && tc6
                                .child(*e, "variable")
                                .and_then(|x| x.text())
                                .map(str::trim)
                                == Some(name))
                });
                let Some(out) = out else {
                    self.refuse(body, format!("transition `{name}`'s body has no output variable or coil named `{name}`"));
                    return None;
                };
                let Some(cpi) = tc6.child(out, "connectionPointIn") else {
                    self.refuse(out, "an unconnected output of a transition body");
                    return None;
                };
                match self.expression(&by_id, cpi) {
                    Ok(mut text) => {
                        if out.attribute("negated") == Some("true") {
                            text = format!("NOT ({text})");
                        }
                        Some(Code::Expr { text, node: def })
                    }
                    Err((at, what)) => {
                        self.refuse(at, what);
                        None
                    }
                }
            }
            other => {
                self.refuse(body, format!("the {other} body of transition `{name}`"));
                None
            }
        }
    }

    /// The ST expression for what feeds `cpi` (Beremiz's `ComputeExpression`, for the elements
    /// that make an expression without a function block instance): OR of its connections.
    fn expression(
        &mut self,
        by_id: &HashMap<&'a str, Node<'a, 'i>>,
        cpi: Node<'a, 'i>,
    ) -> Result<String, (Node<'a, 'i>, String)> {
        let mut terms = Vec::new();
        for c in cpi
            .children()
            .filter(|c| c.is_element() && c.tag_name().name() == "connection")
        {
            let Some(n) = c
                .attribute("refLocalId")
                .and_then(|i| by_id.get(i).copied())
            else {
                return Err((c, "a connection to an element that does not exist".into()));
            };
            terms.push(self.element_expr(by_id, n, c.attribute("formalParameter"), 0)?);
        }
        match terms.len() {
            0 => Err((cpi, "an unconnected transition condition".into())),
            1 => Ok(terms.pop().unwrap_or_default()),
            _ => Ok(format!("({})", terms.join(" OR "))),
        }
    }

    fn element_expr(
        &mut self,
        by_id: &HashMap<&'a str, Node<'a, 'i>>,
        n: Node<'a, 'i>,
        link: Option<&str>,
        depth: usize,
    ) -> Result<String, (Node<'a, 'i>, String)> {
        if depth > 200 {
            return Err((n, "a loop of connections in a transition condition".into()));
        }
        let tc6 = self.tc6;
        let neg = |s: String, n: Node| {
            if n.attribute("negated") == Some("true") {
                format!("NOT {s}")
            } else {
                s
            }
        };
        match n.tag_name().name() {
            "inVariable" | "inOutVariable" => {
                let e = tc6
                    .child(n, "expression")
                    .and_then(|x| x.text())
                    .unwrap_or("")
                    .trim();
                Ok(neg(format!("({e})"), n))
            }
            "leftPowerRail" => Ok("TRUE".into()),
            "contact" => {
                let v = tc6
                    .child(n, "variable")
                    .and_then(|x| x.text())
                    .unwrap_or("")
                    .trim();
                if matches!(n.attribute("edge"), Some("rising" | "falling")) {
                    return Err((n, "an edge contact in a transition condition (Beremiz computes it with an R_TRIG/F_TRIG instance)".into()));
                }
                let me = neg(format!("({v})"), n);
                let before = match tc6.child(n, "connectionPointIn") {
                    Some(cpi) => self.expression(by_id, cpi)?,
                    None => {
                        return Err((n, "an unconnected element in a transition condition".into()))
                    }
                };
                Ok(if before == "TRUE" {
                    me
                } else {
                    format!("({before} AND {me})")
                })
            }
            "block" => self.block_expr(by_id, n, link),
            other => Err((n, format!("a `{other}` in a transition condition"))),
        }
    }

    /// A block in a condition (Beremiz's `GenerateBlock`): a function block instance called
    /// as `Inst(IN := …);`, read as `Inst.Q`; a BOOL function computed into a temporary
    /// `sfc__NOT42_OUT` (Beremiz's `_TMP_NOT42_OUT`); each once, in COMPUTE_FUNCTION_BLOCKS.
    fn block_expr(
        &mut self,
        by_id: &HashMap<&'a str, Node<'a, 'i>>,
        n: Node<'a, 'i>,
        link: Option<&str>,
    ) -> Result<String, (Node<'a, 'i>, String)> {
        let tc6 = self.tc6;
        let ty = n.attribute("typeName").unwrap_or("").to_owned();
        let id = n.attribute("localId").unwrap_or("");
        let mut args = Vec::new();
        let first = !self.computed.contains(&n.range().start);
        if first {
            self.computed.insert(n.range().start);
            if let Some(iv) = tc6.child(n, "inputVariables") {
                for v in tc6.children(iv, "variable") {
                    if matches!(v.attribute("edge"), Some("rising" | "falling")) {
                        return Err((v, "an edge input in a transition condition".into()));
                    }
                    let p = v.attribute("formalParameter").unwrap_or("").to_owned();
                    if let Some(cpi) = tc6.child(v, "connectionPointIn") {
                        if cpi
                            .children()
                            .any(|c| c.is_element() && c.tag_name().name() == "connection")
                        {
                            let e = self.expression(by_id, cpi)?;
                            let e = if v.attribute("negated") == Some("true") {
                                format!("NOT {e}")
                            } else {
                                e
                            };
                            args.push((p, e));
                        }
                    }
                }
            }
        }
        let outputs: Vec<Node> = tc6
            .child(n, "outputVariables")
            .map(|o| tc6.children(o, "variable").collect())
            .unwrap_or_default();
        let out = match link.filter(|l| !l.is_empty()) {
            Some(l) => outputs
                .iter()
                .find(|o| o.attribute("formalParameter") == Some(l))
                .copied(),
            None => outputs.first().copied(),
        };
        let Some(out) = out else {
            return Err((
                n,
                format!("block `{ty}` without the output the condition reads"),
            ));
        };
        let param = out.attribute("formalParameter").unwrap_or("").to_owned();
        let negate = |s: String| {
            if out.attribute("negated") == Some("true") {
                format!("(NOT {s})")
            } else {
                s
            }
        };
        if let Some(inst) = n.attribute("instanceName") {
            if first {
                let list: Vec<String> = args.iter().map(|(p, e)| format!("{p} := {e}")).collect();
                self.compute.push(format!("{inst}({});", list.join(", ")));
            }
            return Ok(negate(format!("{inst}.{param}")));
        }
        let up = ty.to_ascii_uppercase();
        let temp = format!("sfc__{ty}{id}_{param}");
        if first {
            let vals: Vec<&str> = args.iter().map(|(_, e)| e.as_str()).collect();
            let e = match (up.as_str(), vals.as_slice()) {
                ("NOT", [a]) => format!("NOT {a}"),
                ("AND" | "OR" | "XOR", [_, _, ..]) => vals.join(&format!(" {up} ")),
                ("GT" | "GE" | "EQ" | "NE" | "LE" | "LT", [a, b]) => {
                    let op = match up.as_str() {
                        "GT" => ">",
                        "GE" => ">=",
                        "EQ" => "=",
                        "NE" => "<>",
                        "LE" => "<=",
                        _ => "<",
                    };
                    format!("{a} {op} {b}")
                }
                _ => {
                    return Err((n, format!("the function `{ty}` with {} connected inputs in a transition condition (only NOT, AND, OR, XOR and comparisons are executed there)", vals.len())))
                }
            };
            self.compute.push(format!("{temp} := {e};"));
            self.temps.push(temp.clone());
        }
        Ok(negate(temp))
    }

    /// `ComputeSFCStep`, with `ComputeSFCAction` and `ComputeSFCTransition`.
    fn compute_step(
        &mut self,
        name: &str,
        c: &mut Chart<'a, 'i>,
        done_steps: &mut std::collections::HashSet<String>,
        done_trs: &mut std::collections::HashSet<usize>,
    ) {
        if !done_steps.insert(name.to_owned()) {
            return;
        }
        let Some(info) = self.steps.get_mut(name) else {
            return;
        };
        let assocs = std::mem::take(&mut info.assocs);
        let transitions = info.transitions.clone();
        c.steps.push(Step {
            name: name.to_owned(),
            initial: info.initial,
            origin: info.origin,
            assocs,
        });
        let names: Vec<String> = c.steps[c.steps.len() - 1]
            .assocs
            .iter()
            .map(|a| a.action.clone())
            .collect();
        for a in names {
            if let Some((origin, body)) = self.actions.remove(&a) {
                c.actions.push(Action {
                    name: a,
                    origin,
                    body,
                });
            }
        }
        for k in transitions {
            if !done_trs.insert(k) {
                continue;
            }
            let t = &self.trs[k];
            if t.from.is_empty() || t.to.is_empty() {
                let what = if t.from.is_empty() {
                    "previous"
                } else {
                    "next"
                };
                let at = t.origin;
                if self.refused.is_none() {
                    self.refused = Some((
                        at,
                        format!("transition {} not connected to a {what} step", t.id),
                    ));
                }
                continue;
            }
            let Some(cond) = t.cond.clone() else {
                continue;
            };
            let to = t.to.clone();
            c.transitions.push(Transition {
                unit: t.unit.clone(),
                origin: t.origin,
                priority: t.priority,
                from: t.from.clone(),
                to: to.clone(),
                cond,
            });
            for s in to {
                self.compute_step(&s, c, done_steps, done_trs);
            }
        }
    }
}

/// The first non-blank text node inside `n` (an `xhtml:p` or the element itself).
fn text_node<'a, 'i>(n: Node<'a, 'i>) -> Option<Node<'a, 'i>> {
    n.descendants()
        .find(|d| d.is_text() && !d.text().unwrap_or("").trim().is_empty())
}
