//! FBD bodies in the resolver: lowering each body into ladder rungs (once per POU that
//! runs it), through the lowering's view of a POU's scope ([`Env`]).

use super::{Builder, Result};
use plc_diag::{Diagnostic, Invalid, LoadError};
use plc_fbd::lower::{Env, InstanceRef, Names};
use plc_fbd::{FbdPouKind, LoweredCopy};
use plc_model::*;

impl<'a> Builder<'a> {
    /// Lowers every FBD body: the main program's and subroutines' once, a function block type's
    /// once per instance.
    pub(super) fn lower_fbd(&mut self) -> Result<()> {
        let mut bodies = std::mem::take(&mut self.fbd_bodies);
        for pid in self.pous.ids() {
            let Some(i) = self.pous[pid].fbd else {
                continue;
            };
            let draft = &self.pous[pid];
            let names = Names {
                pou: draft.name.clone(),
                rung_prefix: draft.prefix.clone(),
                var_prefix: draft.var_prefix.clone(),
            };
            let origin = self.fbd_origins[i];
            let lowered =
                plc_fbd::lower::lower(&bodies[i], &mut PouEnv { b: self, pou: pid }, &names, pid)
                    .map_err(|e| at_blocks(e, &bodies[i]).at(origin))?;
            if bodies[i].kind == FbdPouKind::FunctionBlock {
                self.keep_typed_body(i, pid, &lowered.typed);
            }
            bodies[i].copies.push(LoweredCopy {
                pou: pid,
                networks: lowered.networks,
                blocks: lowered
                    .blocks
                    .into_iter()
                    .map(|bs| bs.into_iter().map(RungId::relative).collect())
                    .collect(),
            });
            self.pous[pid].lowered = Some(lowered.rungs);
        }
        self.fbd_bodies = bodies;
        Ok(())
    }
}

/// `e` with each problem that names a block and has no place yet placed at that block (where
/// the reader read it: a PLCopen element's line, the element a block the reader added stands
/// for), rather than at the start of its body.
fn at_blocks(mut e: LoadError, body: &plc_fbd::FbdPou) -> LoadError {
    let ds: &mut [Diagnostic] = match &mut e {
        LoadError::Invalid(d) => std::slice::from_mut(&mut **d),
        LoadError::Several(ds) => ds,
        _ => return e,
    };
    for d in ds {
        let Some((net, Some(id))) = &d.location.network else {
            continue;
        };
        let Some(n) = body.networks.iter().find(|n| &n.id == net) else {
            continue;
        };
        if let Some(b) = n.find(*id) {
            d.location.origin = d.location.origin.or(n.block(b).origin);
        }
    }
    e
}

/// The lowering's view of one POU's scope.
struct PouEnv<'b, 'a> {
    b: &'b mut Builder<'a>,
    pou: PouId,
}

impl Env for PouEnv<'_, '_> {
    fn lookup(&self, text: &str) -> std::result::Result<(VarRef, Type), Invalid> {
        self.b.lookup(text, self.pou)
    }

    fn writable(&self, text: &str, what: &'static str) -> std::result::Result<VarId, Invalid> {
        self.b.writable_name(text, self.pou, what)
    }

    fn instance(&self, text: &str) -> std::result::Result<InstanceRef, Invalid> {
        let b = &*self.b;
        let user = |i: usize| {
            let inst = &b.instances[i];
            InstanceRef::User {
                pou: inst.pou.expect("expanded before lowering"),
                fb: inst.fb.clone(),
                inputs: inst.inputs.clone(),
                outputs: inst.outputs.clone(),
            }
        };
        let var = |id: VarId| match b.vars[id.index()].ty {
            Type::Fb(k) => InstanceRef::Builtin(id, k),
            t => InstanceRef::Other(t),
        };
        let pou = self.pou.index();
        if !text.contains('.') {
            if let Some(&id) = b.locals[pou].get(text) {
                return Ok(var(id));
            }
            if let Some(&i) = b.local_instances[pou].get(text) {
                return Ok(user(i));
            }
            if let Some(&id) = b.globals.get(text) {
                return Ok(var(id));
            }
            if let Some(&i) = b.global_instances.get(text) {
                return Ok(user(i));
            }
        }
        let (_, t) = b.lookup(text, self.pou)?;
        Ok(InstanceRef::Other(t))
    }

    fn var(&self, v: VarId) -> &Var {
        &self.b.vars[v.index()]
    }

    fn hidden(&mut self, name: String, ty: Type) -> std::result::Result<VarId, Invalid> {
        let b = &mut *self.b;
        let names = b
            .var_names
            .get_or_insert_with(|| b.vars.iter().map(|v| v.name.clone()).collect());
        if !names.insert(name.clone()) {
            return Err(Invalid::HiddenClash { name });
        }
        let scope = if self.pou.index() == 0 {
            None
        } else {
            Some(self.pou)
        };
        let id = self.b.vars.push(Var {
            name,
            ty,
            class: VarClass::Memory,
            init: ty.zero(),
            scope,
            hidden: true,
        });
        Ok(id)
    }

    fn claim_accumulator(&mut self, v: VarId) -> std::result::Result<(), Invalid> {
        match self.b.accumulated.get(&v) {
            Some(&other) if other != self.pou => Err(Invalid::AccumulatedTwice {
                var: self.b.vars[v.index()].name.clone(),
                first: self.b.pous[other.index()].name.clone(),
                second: self.b.pous[self.pou.index()].name.clone(),
            }),
            _ => {
                self.b.accumulated.insert(v, self.pou);
                Ok(())
            }
        }
    }
}

/// Makes the POU-relative jump targets of a lowered rung absolute.
pub(super) fn relocate_jumps(series: &mut Series, offset: u32) {
    for e in series {
        match e {
            Element::Jmp { target, .. } => *target = target.shifted(offset),
            Element::Or(bs) | Element::Branch(bs) => {
                bs.iter_mut().for_each(|b| relocate_jumps(b, offset))
            }
            _ => {}
        }
    }
}
