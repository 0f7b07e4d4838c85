//! User function blocks: reading the `function_blocks` types (signatures, declarations, no
//! recursion, bodies), expanding each instance into its own POU, and what the resolved program
//! keeps of each type ([`plc_fbd::FbType`]: its interface, and its FBD body in typed form,
//! variables named relative to the type, taken from the lowering of its first instance —
//! every instance resolves the same names in the same scopes; IEC 61131-3 6.6.3).

use super::table::NameTable;
use super::util::check_name;
use super::util::FastMap;
use super::{Builder, FbType, PouDraft, Result};
use crate::fbd_read::FbSig;
use plc_diag::{Invalid, LoadError, Origin};
use plc_fbd::types::{self as fbt, FbTypeBody, Pin, TypedBody, TypedRef, TypedVar};
use plc_fbd::{FbdPou, FbdPouKind};
use plc_model::*;
use plc_syntax as syntax;

impl<'a> Builder<'a> {
    /// Reads `function_blocks`: names and pins first (bodies may use each other), then each
    /// type's declarations (checked on a scratch scope), its body and, for FBD, its networks.
    pub(super) fn function_block_types(
        &mut self,
        fbs: &'a [syntax::FunctionBlock<'a>],
    ) -> Result<()> {
        let mut bodies = Vec::with_capacity(fbs.len());
        for fb in fbs {
            let path = format!("function_blocks.{}", fb.name);
            check_name(&fb.name, || path.clone(), None).map_err(|e| e.at(fb.origin))?;
            if Type::parse(&fb.name).is_some() {
                return Err(LoadError::invalid(
                    None,
                    &path,
                    Invalid::Misplaced {
                        what: "a function block named like a standard type",
                        place: "(rename it)",
                    },
                )
                .at(fb.origin));
            }
            let names = |vs: &[syntax::Var]| -> Vec<String> {
                vs.iter()
                    .filter(|v| v.problem.is_none())
                    .map(|v| v.name.value.to_string())
                    .collect()
            };
            let sig = FbSig {
                inputs: names(&fb.inputs),
                outputs: names(&fb.outputs),
            };
            self.fb_index
                .insert(fb.name.to_string(), self.fb_types.len());
            self.fb_types.push(FbType {
                name: fb.name.to_string(),
                path,
                inputs: &fb.inputs,
                outputs: &fb.outputs,
                vars: &fb.vars,
                rungs: None,
                fbd: None,
                sig,
                model: fbt::FbType {
                    name: fb.name.to_string(),
                    inputs: Vec::new(),
                    outputs: Vec::new(),
                    locals: Vec::new(),
                    nested: Vec::new(),
                    body: FbTypeBody::Ladder,
                },
            });
            bodies.push(&fb.body);
        }
        // Declarations on a scratch scope (rolled back), and which types each type instantiates.
        let mut uses: Vec<Vec<(usize, String, Origin)>> = Vec::new();
        for f in 0..self.fb_types.len() {
            let (vars_mark, inst_mark) = (self.vars.len(), self.instances.len());
            let scratch = self.locals.next_id();
            self.locals.push(NameTable::default());
            self.local_instances.push(NameTable::default());
            let (path, prefix) = (
                self.fb_types[f].path.clone(),
                format!("{}.", self.fb_types[f].name),
            );
            let decls = [
                ("inputs", self.fb_types[f].inputs, true),
                ("outputs", self.fb_types[f].outputs, true),
                ("vars", self.fb_types[f].vars, false),
            ];
            for (key, decl, elementary) in decls {
                self.declare_vars(
                    decl,
                    &format!("{path}.{key}"),
                    Some((scratch, prefix.clone())),
                    elementary,
                );
            }
            self.interface(f, scratch);
            uses.push(
                self.instances[inst_mark..]
                    .iter()
                    .filter_map(|i| Some((*self.fb_index.get(&i.fb)?, i.path.clone(), i.origin)))
                    .collect(),
            );
            self.vars.truncate(vars_mark);
            self.instances.truncate(inst_mark);
            self.pending.clear();
            self.locals.pop();
            self.local_instances.pop();
        }
        // No type may contain itself (directly or through others).
        for start in 0..self.fb_types.len() {
            let mut seen = vec![false; self.fb_types.len()];
            seen[start] = true;
            let mut stack: Vec<(usize, usize)> = vec![(start, 0)];
            while let Some(&mut (f, ref mut i)) = stack.last_mut() {
                if let Some((g, p, origin)) = uses[f].get(*i) {
                    *i += 1;
                    if *g == start {
                        let mut chain: Vec<&str> = stack
                            .iter()
                            .map(|&(x, _)| self.fb_types[x].name.as_str())
                            .collect();
                        chain.push(&self.fb_types[start].name);
                        return Err(LoadError::invalid(
                            None,
                            p,
                            Invalid::FbRecursion {
                                name: self.fb_types[start].name.clone(),
                                chain: chain.join(" → "),
                            },
                        )
                        .at(*origin));
                    }
                    if !seen[*g] {
                        seen[*g] = true;
                        stack.push((*g, 0));
                    }
                } else {
                    stack.pop();
                }
            }
        }
        // Bodies.
        for (f, body) in bodies.into_iter().enumerate() {
            let path = self.fb_types[f].path.clone();
            match body {
                None => {} // reported by the reader
                Some(syntax::Body::Rungs(r)) => self.fb_types[f].rungs = Some(r),
                Some(syntax::Body::Fbd(j)) => {
                    let name = self.fb_types[f].name.clone();
                    let body =
                        self.read_fbd(j, &format!("{path}.fbd"), &name, FbdPouKind::FunctionBlock)?;
                    self.fb_types[f].fbd = Some(self.fbd_bodies.len());
                    self.fb_types[f].model.body = FbTypeBody::Fbd {
                        pou: self.fbd_bodies.len(),
                        typed: None,
                    };
                    self.fbd_bodies.push(body);
                    self.fbd_origins.push(j.origin);
                }
            }
        }
        Ok(())
    }

    /// Gives instance `idx` its POU: the function block's variables declared as `G1.name`, its
    /// body (ladder rungs now, FBD lowered later), nested instances right after it.
    pub(super) fn expand(&mut self, idx: usize, stack: &mut Vec<String>) -> Result<()> {
        let Some(&f) = self.fb_index.get(&self.instances[idx].fb) else {
            return Ok(()); // declared only for user types (checked when declared)
        };
        let (display, ipath, iorigin) = (
            self.instances[idx].display.clone(),
            self.instances[idx].path.clone(),
            self.instances[idx].origin,
        );
        if stack.contains(&self.fb_types[f].name) {
            let mut chain = stack.clone();
            chain.push(self.fb_types[f].name.clone());
            return Err(LoadError::invalid(
                None,
                &ipath,
                Invalid::FbRecursion {
                    name: self.fb_types[f].name.clone(),
                    chain: chain.join(" → "),
                },
            )
            .at(iorigin));
        }
        if self.pous.iter().any(|p| p.name == display) {
            return Err(LoadError::invalid(
                None,
                &format!("{ipath}.name"),
                Invalid::Misplaced {
                    what: "a function block instance named like the program or a subroutine",
                    place: "(rename one of them)",
                },
            )
            .at(self.instances[idx].name_origin));
        }
        let pou = self.pous.next_id();
        let t = &self.fb_types[f];
        let (path, inputs, outputs, vars, rungs, fbd) =
            (t.path.clone(), t.inputs, t.outputs, t.vars, t.rungs, t.fbd);
        let mut draft = PouDraft::new(
            display.clone(),
            PouKind::Subroutine,
            format!("{path}.rungs"),
        );
        draft.rungs = rungs.unwrap_or_default();
        draft.fbd = fbd;
        draft.prefix = format!("{display}:");
        draft.var_prefix = format!("{display}.");
        draft.callable = false;
        self.pous.push(draft);
        self.locals.push(NameTable::default());
        self.local_instances.push(NameTable::default());
        let mark = self.pending.len();
        let prefix = format!("{display}.");
        for (key, decl, elementary) in [
            ("inputs", inputs, true),
            ("outputs", outputs, true),
            ("vars", vars, false),
        ] {
            self.declare_vars(
                decl,
                &format!("{path}.{key}"),
                Some((pou, prefix.clone())),
                elementary,
            );
        }
        self.phase_end()?;
        let locals = &self.locals[pou.index()];
        let pins = |names: &[String]| {
            names
                .iter()
                .filter_map(|n| Some((n.clone(), *locals.get(n)?)))
                .collect::<Vec<_>>()
        };
        let (ins, outs) = (
            pins(&self.fb_types[f].sig.inputs),
            pins(&self.fb_types[f].sig.outputs),
        );
        let inst = &mut self.instances[idx];
        inst.pou = Some(pou);
        inst.inputs = ins;
        inst.outputs = outs;
        stack.push(self.fb_types[f].name.clone());
        let nested: Vec<usize> = self.pending.drain(mark..).collect();
        for n in nested {
            self.expand(n, stack)?;
        }
        stack.pop();
        Ok(())
    }
}

impl Builder<'_> {
    /// The interface of type `f` as declared on the scratch scope `pou`, in declaration order
    /// (declarations with errors are left out: they are reported).
    fn interface(&mut self, f: usize, pou: PouId) {
        let (locals, instances) = (
            &self.locals[pou.index()],
            &self.local_instances[pou.index()],
        );
        let var = |v: &syntax::Var| {
            let id = *locals.get(v.name.value.as_ref())?;
            let var = &self.vars[id.index()];
            Some(fbt::FbVar {
                name: v.name.value.to_string(),
                ty: var.ty,
                init: var.init,
            })
        };
        let t = &self.fb_types[f];
        let inputs = t.inputs.iter().filter_map(var).collect();
        let outputs = t.outputs.iter().filter_map(var).collect();
        let locals_ = t.vars.iter().filter_map(var).collect();
        let nested = t
            .vars
            .iter()
            .filter_map(|v| {
                let i = *instances.get(v.name.value.as_ref())?;
                let ty = *self.fb_index.get(&self.instances[i].fb)?;
                Some(fbt::Nested {
                    name: v.name.value.to_string(),
                    ty: self.fb_types.id(ty),
                })
            })
            .collect();
        let m = &mut self.fb_types[f].model;
        (m.inputs, m.outputs, m.locals, m.nested) = (inputs, outputs, locals_, nested);
    }

    /// Gives the type whose FBD body is `fbd_bodies[body]` its typed form from the lowering of
    /// its instance `pou` (the first one lowered).
    pub(super) fn keep_typed_body(&mut self, body: usize, pou: PouId, typed: &TypedBody<VarRef>) {
        let Some(f) = self.fb_types.iter().position(|t| t.fbd == Some(body)) else {
            return;
        };
        if let FbTypeBody::Fbd { typed: Some(_), .. } = &self.fb_types[f].model.body {
            return;
        }
        let own = self.own_vars(f, pou);
        let r = |v: &VarRef| TypedRef {
            var: own.get(&v.var).copied().unwrap_or(TypedVar::Global(v.var)),
            field: v.field,
        };
        let pin = |p: &Pin<VarRef>| match p {
            Pin::Arc { block, output } => Pin::Arc {
                block: *block,
                output: *output,
            },
            Pin::Variable(v) => Pin::Variable(r(v)),
            Pin::Constant(c) => Pin::Constant(*c),
        };
        let networks = typed
            .networks
            .iter()
            .map(|n| fbt::TypedNetwork {
                blocks: n
                    .blocks
                    .iter()
                    .map(|b| fbt::TypedBlock {
                        inputs: b.inputs.iter().map(|p| p.as_ref().map(pin)).collect(),
                        cond: b.cond.as_ref().map(pin),
                        outputs: b
                            .outputs
                            .iter()
                            .map(|vs| vs.iter().map(r).collect())
                            .collect(),
                    })
                    .collect(),
            })
            .collect();
        if let FbTypeBody::Fbd { typed, .. } = &mut self.fb_types[f].model.body {
            *typed = Some(TypedBody { networks });
        }
    }

    /// The variables of instance POU `pou` of type `f`, as the type names them.
    fn own_vars(&self, f: usize, pou: PouId) -> FastMap<VarId, TypedVar> {
        let m = &self.fb_types[f].model;
        let locals = &self.locals[pou.index()];
        let mut own = FastMap::default();
        let slots = [
            (&m.inputs, fbt::Slot::Input as fn(u32) -> fbt::Slot),
            (&m.outputs, fbt::Slot::Output),
            (&m.locals, fbt::Slot::Local),
        ];
        for (vars, slot) in slots {
            for (i, v) in vars.iter().enumerate() {
                if let Some(&id) = locals.get(&v.name) {
                    own.insert(id, TypedVar::Own(slot(i as u32)));
                }
            }
        }
        for (n, nested) in m.nested.iter().enumerate() {
            let Some(&i) = self.local_instances[pou.index()].get(&nested.name) else {
                continue;
            };
            let inst = &self.instances[i];
            let pins = inst
                .inputs
                .iter()
                .enumerate()
                .map(|(p, v)| (fbt::Slot::Input(p as u32), v));
            let outs = inst
                .outputs
                .iter()
                .enumerate()
                .map(|(p, v)| (fbt::Slot::Output(p as u32), v));
            for (slot, (_, id)) in pins.chain(outs) {
                let nested = n as u32;
                own.insert(*id, TypedVar::Member { nested, slot });
            }
        }
        own
    }

    /// Every type as the resolved program keeps it; `bodies` are the FBD bodies in reading
    /// order, which the resolved program lists main program and subroutines first.
    pub(super) fn fb_type_models(&self, bodies: &[FbdPou]) -> Vec<fbt::FbType> {
        let is_fb = |p: &FbdPou| p.kind == FbdPouKind::FunctionBlock;
        let others = bodies.iter().filter(|p| !is_fb(p)).count();
        let listed = |i: usize| {
            let before = bodies[..i]
                .iter()
                .filter(|p| is_fb(p) == is_fb(&bodies[i]))
                .count();
            if is_fb(&bodies[i]) {
                others + before
            } else {
                before
            }
        };
        self.fb_types
            .iter()
            .map(|t| {
                let mut m = t.model.clone();
                if let FbTypeBody::Fbd { pou, .. } = &mut m.body {
                    *pou = listed(*pou);
                }
                m
            })
            .collect()
    }
}
