//! The scan interpreter: executes a [`Program`] scan by scan on virtual time.
//!
//! # Use
//! ```
//! use plc_exec::{ExecConfig, Layout, Machine};
//! use plc_model::Value;
//! let p = plc_load::program_from_json(r#"{"program": "p",
//!     "vars": [{"name": "a", "type": "BOOL", "class": "input"}, {"name": "q", "type": "BOOL", "class": "output"}],
//!     "rungs": [{"id": "R1", "ld": [{"contact": "a"}, {"coil": "q"}]}]}"#).unwrap();
//! let m = Machine::new(&p, Layout::dense(&p), &ExecConfig::default()).unwrap();
//! let mut state = m.initial_state();
//! let mut faults = Vec::new();
//! let (a, q) = (p.vars().id(0), p.vars().id(1));
//! m.set_inputs(&mut state, &[(a, Value::Bool(true))]);
//! m.run_scan(&mut state, 0, &mut faults);
//! assert_eq!(m.value(&state, q).as_bool(), Some(true));
//! ```
//!
//! # Scan semantics (the contract)
//! - **A scan**: the caller copies the scan's input values into the input variables
//!   ([`Machine::set_inputs`]); [`Machine::run_scan`] executes the main program's rungs from the
//!   first; the outputs are then the output variables. All variables keep their values from scan
//!   to scan (everything is retentive); initial values are the declarations' `init` (zero when
//!   absent; instances start with every field and internal state zero).
//! - **Virtual time**: scan `k` (0-based) runs at `now = k × cycle_ms` ms; timers read only
//!   `now`, never a clock.
//! - **Power flow** through a series starts TRUE at the left rail:
//!   - contact: `power &= v` (negated: `&= !v`). Edge contact: `out = power && edge`, edge being
//!     `v && !mem` (rising) or `!v && mem` (falling); then `mem := v`. The memory is the hidden
//!     BOOL of `ContactKind::Rising{memory}` and is updated at *every* evaluation of the contact,
//!     whatever the incoming power.
//!   - compare: `power &= a OP b`, in the operands' type (INT, DINT, TIME as integers, REAL as
//!     IEEE 754 `f32`: any comparison with NaN is false except NE).
//!   - or: every branch is evaluated (in order, from the same power in; no short circuit, so edge
//!     contacts in any branch always update their memory); power out = OR of the branches.
//!   - coil: `v := power` (negated: `!power`); set: if power, `v := TRUE`; reset: if power,
//!     `v := FALSE`.
//!   - branch: each branch series gets the same power in, in order; power out = power in.
//!   - TON/TOF/TP (IN = power, PT operand, power out = Q), IEC 61131-3 on virtual time:
//!     TON: IN false → Q false, ET 0; IN true → start = now on the first such evaluation,
//!     `ET = min(now − start, PT)`, `Q = ET ≥ PT`. TOF: IN true → Q true, ET 0; IN falling →
//!     start = now; while IN false and timing, `ET = min(now − start, PT)` and Q false once
//!     `ET ≥ PT` (timing then stops; ET stays PT). TP: a rising IN while not pulsing starts a
//!     pulse (start = now); while pulsing (IN is ignored) Q true and `ET = now − start`; at the
//!     evaluation where `ET ≥ PT`: Q false, pulse over, ET = PT. When not pulsing, ET stays as it
//!     is while IN is true and becomes 0 as soon as IN is false (already at the evaluation that
//!     ends the pulse, if IN is false then). The PT field is the PT of the last evaluation.
//!   - CTU (CU = power, R, PV): if R, CV := 0, else if CU rose since this instance's previous
//!     evaluation and `CV < 32767`, CV += 1; `Q = CV ≥ PV`. CTD (CD = power, LD, PV): if LD,
//!     CV := PV, else if CD rose and `CV > −32768`, CV −= 1; `Q = CV ≤ 0`. Power out = Q. The
//!     previous CU/CD is recorded at every evaluation (also while R or LD holds). PV field = the
//!     PV of the last evaluation.
//!   - move: if power, `to := from`; arithmetic ADD SUB MUL DIV MOD: if power, `out := a op b`;
//!     power out = power in. INT (16 bit), DINT and TIME (32 bit ms) wrap in two's complement;
//!     DIV truncates toward zero and MOD takes the sign of the dividend (IEC); an integer DIV or
//!     MOD by zero gives 0 and records [`FaultKind::DivByZero`]; REAL is IEEE 754 `f32` (DIV by
//!     zero gives ±inf or NaN, no fault).
//!   - range fault: if power, records [`FaultKind::IndexRange`] (a PLCopen ST array subscript
//!     outside its bounds, lowered to a rung that reaches it only then); power out = power in.
//!   - jmp: if power, execution continues at the first element of the target rung; nothing after
//!     the jump in this rung is evaluated. ret: if power, the current POU ends (in the main
//!     program: the scan ends). end: if power, the scan ends. call: if power, the subroutine runs
//!     from its first rung until its end or a taken ret, then this rung's series continues with
//!     the same power. Subroutine locals are ordinary retentive variables.
//!   - FOR rung (`Element::For` last in its rung): if the head rung's power is TRUE,
//!     `var := from` and go to TEST, otherwise to the rung after the NEXT. TEST: if `var ≤ to`
//!     (integer compare; `to` is re-read at every test) the body (the next rung) runs, otherwise
//!     control goes to the rung after the NEXT. NEXT rung: `var := var + 1` (wrapping in var's
//!     type), back to TEST, without re-evaluating the head rung's conditions. After a normal exit
//!     `var` holds the first value that failed the test.
//!   - Elements in rungs that control skips (jumped over, loop not entered, subroutine not called)
//!     are not evaluated at all in that scan: their timers do not see IN, their edge memories and
//!     counters' previous CU keep their values.
//! - **Iteration cap** ([`ExecConfig::loop_cap`], default 100 000): a *loop-back rung* is a NEXT
//!   rung or a rung holding a backward jump (to itself or an earlier rung of its POU). Each
//!   loop-back rung may loop back (NEXT: back to the FOR test; a taken backward jump: to its
//!   target) at most `loop_cap` times per scan, counted in a hidden counter of its own that
//!   [`Machine::begin_scan`] zeroes at the start of every scan (a subroutine's loop-back rungs
//!   count over all its calls in the scan). A refused loop-back is not performed and control
//!   goes on as if the loop had ended there: a refused NEXT does not increment the index and
//!   continues at the rung after the NEXT (the loop's exit); a refused backward jump is not taken
//!   and acts as a jump without power: the power after it in its series is FALSE and the rest of
//!   the rung is evaluated as usual (then the next rung, or the rung's other transfers). The
//!   first refusal of a rung in a scan records
//!   [`FaultKind::LoopCap`] on that rung; further refusals of the same rung in the same scan
//!   (control can come back through another loop-back rung) are silent. The rule is local to one
//!   rung and deterministic, so a parallel scan reproduces it exactly; a scan performs at most
//!   `loop_cap` × (number of loop-back rungs) loop-backs and never hangs.
//! - **Scan budget** ([`ExecConfig::scan_budget`], default [`DEFAULT_SCAN_BUDGET`]): a CALL
//!   charges the callee's rung count, a loop-back (after the cap allowed it) the rungs it goes
//!   back over, to the *task* of the scan it runs in (a main-program rung, or a main-program
//!   loop, with all they call; the `budget` module). The charge that takes a task past the
//!   budget records [`FaultKind::ScanBudget`] and is refused, as is every later charge of the
//!   task in the scan: a refused CALL does not run the subroutine (the rung goes on with the
//!   same power), a refused loop-back acts as one the cap refused. Counted per task, it is the
//!   same whichever worker of a parallel scan runs the task.
//! - **Faults** are data ([`Fault`]: scan, rung, kind), appended to a caller-owned `Vec` (no
//!   allocation when there are none, or when its capacity is reused).
//!
//! # Design
//! The model is lowered once ([`Machine::new`]) into a flat array of 16-byte instructions over
//! the state's bytes, every value stored in its type's width (BOOL one byte, INT two, DINT,
//! REAL and TIME four; instances small structs: [`Layout`]) at an address aligned to it, so a
//! thousand BOOLs take 1,000 bytes, not 8,000; a scan walks it with no allocation, hashing or
//! strings. Contacts on BOOLs and coils are a byte load, an and (xor for negation) and a byte
//! store; constants are bytes of the state too, so every operand is one typed load; `or`/`branch` keep their
//! saved powers in a 64-bit register. The cost of an interpreter is its dispatches, and above
//! all the mispredicted ones, so a rung of plain contacts (in series and `or`s, up to eight)
//! and one output is one instruction (`fuse`: the contacts' bytes index a shared table that
//! gives the output's new value, without a branch), and runs of such rungs loop without going
//! back through the dispatch; any other rung that starts with plain contacts starts with one
//! instruction for its marker and those contacts. Elsewhere consecutive contacts are fused (up
//! to six in one instruction when their addresses fit in 16 bits) and every output (coil,
//! negated coil, set, reset) is one instruction computed without a branch. The instruction,
//! operand and table reads are unchecked, behind a check of the lowered code when the machine
//! is built. The address of each variable comes from a [`Layout`], so a
//! parallel executor can permute and pad variables. Memory is accessed through the [`Store`]
//! trait's typed loads and stores, monomorphised, so the same interpreter runs on a plain `[u8]`
//! and on a shared store. A state's memory ([`Mem`]) starts on a 64-byte line.
//!
//! For the parallel executor (tasks of `analysis::schedule`): [`Machine::run_from`] runs from a
//! rung while control stays in a region (`inside`) and reports where it left ([`Exit`]);
//! [`Machine::run_scan`] is [`begin_scan`](Machine::begin_scan) then `run_from(first main rung,
//! everywhere)`. Per-scan context (time, scan index, fault sink) is explicit in [`ScanCtx`]; the
//! loop counters are `u64`s of the state, after the layout's variables (one 64-byte line each),
//! so a loop task's counter lives with the data it runs on. [`parallel`] runs the combined schedule on
//! several threads, bit-identical to [`Machine::run_scan`].
#![warn(missing_docs)]
#![warn(clippy::undocumented_unsafe_blocks)]
// `unsafe` only where it is allowed by name: every raw memory access is in `raw` (the state's
// lines, the checked code's unchecked reads, the sequential and the shared stores, the SIMD
// packing); the other modules that say `unsafe` only call `raw`'s `unsafe fn`s (or their own,
// built on them) and argue each call's `# Safety` in their file: the interpreter (`run`) and
// the parallel machine's `items`, `claimed`, `exchange` and `workers`.
#![deny(unsafe_code)]

mod access;
pub mod budget;
mod fb;
pub mod functions;
mod fuse;
#[cfg(test)]
mod fuse_tests;
mod layout;
mod line;
mod lower;
mod mem;
mod output_mode;
pub mod parallel;
#[allow(unsafe_code)]
mod raw;
#[allow(unsafe_code)]
mod run;
mod store;
pub mod strings;
mod value;

pub use access::Span;
pub use budget::DEFAULT_SCAN_BUDGET;
pub use layout::{
    field_offset, parts, type_align, type_size, Layout, LayoutError, Repr, COUNTER_BYTES,
    TIMER_BYTES,
};
pub use lower::LowerError;
pub use mem::{Mem, LINE_BYTES};
pub use store::{load_bits, Addr, Store, Word};
pub use value::{load_value, store_value, VarValue};

use plc_model::{Arena, Program, RungId, Type, Value, VarClass, VarId, VarRef};

/// Execution parameters.
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub struct ExecConfig {
    /// Virtual scan period: scan `k` runs at `k × cycle_ms` ms.
    pub cycle_ms: u32,
    /// Loop-backs allowed per loop-back rung (a NEXT, or a rung with a backward jump) per scan.
    pub loop_cap: u32,
    /// Rungs each task of a scan may charge with its calls and loop-backs
    /// ([`DEFAULT_SCAN_BUDGET`]; see the scan semantics above).
    pub scan_budget: u64,
}

impl Default for ExecConfig {
    /// 10 ms cycle, 100 000 loop-backs per loop-back rung and scan, [`DEFAULT_SCAN_BUDGET`].
    fn default() -> Self {
        ExecConfig {
            cycle_ms: 10,
            loop_cap: 100_000,
            scan_budget: DEFAULT_SCAN_BUDGET,
        }
    }
}

/// The memory of a running program: every variable's bytes (see [`Layout`]), the loop counters
/// and the constants, on 64-byte lines.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct State {
    mem: Mem,
}

impl State {
    /// The state's bytes.
    #[inline]
    pub fn bytes(&self) -> &[u8] {
        &self.mem
    }

    /// The state's bytes, to write.
    #[inline]
    pub fn bytes_mut(&mut self) -> &mut [u8] {
        &mut self.mem
    }
}

/// What went wrong in a scan.
#[derive(Copy, Clone, Debug, PartialEq, Eq, Hash)]
pub enum FaultKind {
    /// An integer DIV or MOD by zero (the result was 0).
    DivByZero,
    /// A loop-back rung was refused a loop-back past the iteration cap (the loop was left there).
    LoopCap,
    /// A call or loop-back would have taken its task of the scan past the scan budget: it was
    /// refused, and so is every later one of the task in the scan.
    ScanBudget,
    /// An array subscript outside its bounds (a read gave the type's default, a write wrote
    /// nothing).
    IndexRange,
}

impl FaultKind {
    /// Short name (`div-by-zero`, `loop-cap`, `scan-budget`, `index-range`).
    pub fn name(self) -> &'static str {
        match self {
            FaultKind::DivByZero => "div-by-zero",
            FaultKind::LoopCap => "loop-cap",
            FaultKind::ScanBudget => "scan-budget",
            FaultKind::IndexRange => "index-range",
        }
    }
}

/// A fault: in which scan, at which rung (of any POU), what.
#[derive(Copy, Clone, Debug, PartialEq, Eq, Hash)]
pub struct Fault {
    /// Scan index, 0-based.
    pub scan: u64,
    /// The rung whose element faulted.
    pub rung: RungId,
    /// What happened.
    pub kind: FaultKind,
}

/// Where control went when [`Machine::run_from`] returned.
#[derive(Copy, Clone, Debug, PartialEq, Eq, Hash)]
pub enum Exit {
    /// To the start of this (main-program) rung, which is outside the region.
    Rung(RungId),
    /// From a NEXT back to the test of this FOR head rung, which is outside the region. (Never
    /// happens when the region is a task of the combined schedule: a FOR head and its NEXT are
    /// always in the same loop task.)
    ForTest(RungId),
    /// The scan is over: the main program ended (last rung, RET, END).
    Stop,
}

/// Per-scan execution context.
#[derive(Debug)]
pub struct ScanCtx<'f> {
    /// Scan index, 0-based (recorded in faults).
    pub scan: u64,
    /// Virtual time of the scan, ms.
    pub now: i64,
    /// Where faults are appended.
    pub faults: &'f mut Vec<Fault>,
    /// What the task running now has charged to the scan budget.
    budget: BudgetSpent,
}

/// The scan budget a task has spent: the budget task of the last charge (none yet in this
/// context) and the rungs charged since that task's first charge.
#[derive(Copy, Clone, Debug, Default)]
struct BudgetSpent {
    task: Option<u32>,
    rungs: u64,
}

#[derive(Copy, Clone, Debug)]
struct VarInfo {
    ty: Type,
    class: VarClass,
}

/// A lowered program with its layout, ready to run scans. Immutable and `Sync`: one machine can
/// drive many states, and many threads can run it at once on disjoint (or shared) stores.
#[derive(Debug)]
pub struct Machine {
    /// The lowered code (instructions, their operands, entries, loop counters, constants, state
    /// size, dialect), checked once for the interpreter's unchecked accesses.
    code: raw::CheckedCode,
    /// The budget task of each rung (`budget::tasks`).
    budget_task: Vec<Option<u32>>,
    main_first: RungId,
    vars: Arena<VarId, VarInfo>,
    inits: Vec<Value>,
    layout: Layout,
    config: ExecConfig,
}

impl Machine {
    /// Lowers `program` with `layout` (which must have been built for it). Fails only for a
    /// layout of another program, `or`/`branch` nested beyond the 64-bit power stack, or a
    /// program too large for 32-bit addresses.
    pub fn new(
        program: &Program,
        layout: Layout,
        config: &ExecConfig,
    ) -> Result<Machine, LowerError> {
        Machine::build(program, layout, config, true)
    }

    /// [`Machine::new`] with only the general instructions (no fused rungs): the reference the
    /// fused instructions are tested against.
    #[cfg(test)]
    pub(crate) fn new_unfused(
        program: &Program,
        layout: Layout,
        config: &ExecConfig,
    ) -> Result<Machine, LowerError> {
        Machine::build(program, layout, config, false)
    }

    fn build(
        program: &Program,
        layout: Layout,
        config: &ExecConfig,
        fuse: bool,
    ) -> Result<Machine, LowerError> {
        // What makes the interpreter's unchecked accesses sound is checked here, once.
        let code = raw::CheckedCode::new(lower::lower(program, &layout, fuse)?);
        Ok(Machine {
            main_first: program.rungs().id(program.main().rungs.start as usize),
            code,
            budget_task: budget::tasks(program),
            vars: program
                .vars()
                .iter()
                .map(|v| VarInfo {
                    ty: v.ty,
                    class: v.class,
                })
                .collect(),
            inits: program.vars().iter().map(|v| v.init).collect(),
            layout,
            config: *config,
        })
    }

    /// The layout the machine was built with.
    pub fn layout(&self) -> &Layout {
        &self.layout
    }

    /// The configuration the machine was built with.
    pub fn config(&self) -> &ExecConfig {
        &self.config
    }

    /// Bytes a state must have: the layout's variables, then (if the program has loop-back
    /// rungs) the loop counters, one per 64-byte line from the next line, then the constants.
    pub fn state_size(&self) -> u32 {
        self.code.size
    }

    /// The loop-back rungs (NEXT rungs and rungs with a backward jump, any POU) with the
    /// addresses of their counters (`u64`), in rung order.
    pub fn loop_counters(&self) -> impl ExactSizeIterator<Item = (RungId, Addr)> + '_ {
        self.code.counters.iter().copied()
    }

    /// Every value the state holds but its constants, in an order that does not depend on the
    /// layout, as (address, width in bytes): each variable's [`parts`] in declaration order,
    /// then the loop counters in rung order. Two machines of one program give lists of the same
    /// length and widths, so states of different layouts compare value by value.
    pub fn canonical_values(&self) -> Vec<(Addr, u32)> {
        let mut out: Vec<(Addr, u32)> = Vec::new();
        for (v, info) in self.vars.iter_enumerated() {
            let at = self.layout.start(v);
            out.extend(parts(info.ty).iter().map(|&(o, w)| (at.offset(o), w)));
        }
        out.extend(self.code.counters.iter().map(|&(_, at)| (at, 8)));
        out
    }

    /// How many times loop-back rung `rung` looped back (or was refused) in the current scan of
    /// `state`; `None` if it is not a loop-back rung.
    pub fn loop_count(&self, state: &State, rung: RungId) -> Option<u64> {
        self.code
            .counters
            .iter()
            .find(|&&(r, _)| r == rung)
            .map(|&(_, at)| state.bytes().load::<u64>(at))
    }

    /// Starts a scan on `store`: zeroes the loop counters. [`run_scan`](Self::run_scan) does it
    /// itself; a caller that runs a scan piecewise with [`run_from`](Self::run_from) /
    /// [`resume`](Self::resume) calls it once before the scan's first piece.
    #[inline]
    pub fn begin_scan<S: Store + ?Sized>(&self, store: &mut S) {
        for &(_, at) in &self.code.counters {
            store.store(at, 0u64);
        }
    }

    /// Number of lowered instructions (rung markers included).
    pub fn instruction_count(&self) -> usize {
        self.code.ops.len()
    }

    /// The state at load: declared initial values, instances zero, padding zero, constants.
    pub fn initial_state(&self) -> State {
        let mut mem = Mem::zeroed(self.code.size as usize);
        for (v, info) in self.vars.iter_enumerated() {
            if !matches!(info.ty, Type::Fb(_)) {
                store_value(&mut mem[..], self.layout.start(v), self.inits[v.index()]);
            }
        }
        for &(at, c) in &self.code.consts {
            store_value(&mut mem[..], at, c);
        }
        State { mem }
    }

    /// The address of a variable or instance field.
    pub fn addr_of(&self, r: VarRef) -> Addr {
        self.layout
            .start(r.var)
            .offset(r.field.map_or(0, field_offset))
    }

    /// Writes input values (normally of input variables; any scalar variable is accepted, which
    /// lets tests force values).
    ///
    /// # Panics
    /// If a variable is an instance, or a value's type is not the variable's type.
    pub fn set_inputs(&self, state: &mut State, inputs: &[(VarId, Value)]) {
        self.set_inputs_in(state.bytes_mut(), inputs);
    }

    /// [`set_inputs`](Self::set_inputs) on a state's bare bytes ([`State::bytes_mut`]).
    ///
    /// # Panics
    /// As `set_inputs`.
    pub fn set_inputs_in(&self, mem: &mut [u8], inputs: &[(VarId, Value)]) {
        for &(var, value) in inputs {
            let ty = self.vars[var.index()].ty;
            assert!(
                value.ty() == ty,
                "input {} is {ty}, given {value} ({})",
                var.raw(),
                value.ty()
            );
            store_value(mem, self.layout.start(var), value);
        }
    }

    /// The per-scan context of scan `scan` (time `scan × cycle_ms`).
    pub fn context<'f>(&self, scan: u64, faults: &'f mut Vec<Fault>) -> ScanCtx<'f> {
        ScanCtx {
            scan,
            now: (scan as i64).wrapping_mul(self.config.cycle_ms as i64),
            faults,
            budget: BudgetSpent::default(),
        }
    }

    /// Runs scan number `scan` (0-based) on `state`: the whole main program from its first rung.
    /// Faults are appended to `faults`.
    ///
    /// # Panics
    /// If `state` has fewer bytes than [`Machine::state_size`].
    pub fn run_scan(&self, state: &mut State, scan: u64, faults: &mut Vec<Fault>) {
        self.run_scan_in(state.bytes_mut(), scan, faults)
    }

    /// [`set_inputs`](Self::set_inputs) then [`run_scan`](Self::run_scan).
    pub fn scan(
        &self,
        state: &mut State,
        scan: u64,
        inputs: &[(VarId, Value)],
        faults: &mut Vec<Fault>,
    ) {
        self.set_inputs(state, inputs);
        self.run_scan(state, scan, faults);
    }

    /// Runs from the start of main-program rung `start` for as long as control stays at rungs for
    /// which `inside` holds (called at every rung start, including `start`; subroutines called on
    /// the way run whole, without consulting it), and returns where control left to.
    pub fn run_from<S, F>(
        &self,
        store: &mut S,
        ctx: &mut ScanCtx<'_>,
        start: RungId,
        inside: F,
    ) -> Exit
    where
        S: Store + ?Sized,
        F: Fn(RungId) -> bool,
    {
        self.resume(store, ctx, Exit::Rung(start), inside)
    }

    /// The value of a variable: its scalar value, or an instance's readable fields.
    pub fn value(&self, state: &State, var: VarId) -> VarValue {
        self.value_in(state.bytes(), var)
    }

    /// [`value`](Self::value) on a state's bare bytes ([`State::bytes`]).
    pub fn value_in(&self, mem: &[u8], var: VarId) -> VarValue {
        VarValue::load(self.vars[var.index()].ty, mem, self.layout.start(var))
    }

    /// The output variables and their values, in declaration order.
    pub fn outputs(&self, state: &State) -> Vec<(VarId, VarValue)> {
        (self.vars.ids())
            .filter(|&v| self.vars[v].class == VarClass::Output)
            .map(|v| (v, self.value(state, v)))
            .collect()
    }
}
