//! Property tests of the clever algorithms against their definitions, on thousands of random
//! inputs: data dependences and levels against the pairwise definition, post-dominators and
//! control dependences against set-based fixpoints, and the combined schedule against the
//! pairwise conditions that make it safe.

// The references index node-by-node matrices (`sets[b][a]`: a post-dominates b), as the
// definitions are written.
#![allow(clippy::needless_range_loop)]

use crate::common;

use plc_deps::analysis::accesses::VarSets;
use plc_deps::analysis::dependences::data_dependences_pairwise;
use plc_deps::analysis::levels::asap_levels;
use plc_deps::analysis::{
    analyse, analyse_with, control_dependences, data_dependences, data_levels, dependence_counts,
    direct_dependences, post_dominators, AnalysisConfig, DepKind, DependenceListing, Listed,
};
use plc_deps::model::VarId;
use proptest::prelude::*;

fn var_sets() -> impl Strategy<Value = (VarSets, VarSets)> {
    (1usize..40).prop_flat_map(|n| {
        let set = proptest::collection::vec(0u32..8, 0..4);
        (
            proptest::collection::vec(set.clone(), n),
            proptest::collection::vec(set, n),
        )
            .prop_map(|(r, w)| {
                let f = |l: Vec<Vec<u32>>| {
                    VarSets::from_lists(
                        l.into_iter()
                            .map(|s| s.into_iter().map(VarId::from_raw).collect::<Vec<_>>()),
                    )
                };
                (f(r), f(w))
            })
    })
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(3000))]

    #[test]
    fn dependences_and_levels_match_the_pairwise_definition((reads, writes) in var_sets()) {
        let fast = data_dependences(&reads, &writes);
        let brute = data_dependences_pairwise(&reads, &writes);
        prop_assert_eq!(&fast, &brute);
        // Levels: ASAP over every pair (reference) == O(accesses) levelling.
        let edges: Vec<(u32, u32)> = brute.iter().map(|d| (d.from, d.to)).collect();
        prop_assert_eq!(data_levels(&reads, &writes), asap_levels(reads.len(), &edges));
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(3000))]

    /// The direct pairs are pairs of the definition, imply every other pair (each pair of the
    /// definition is a path of direct pairs), give the same ASAP levels, and the counts equal
    /// the lengths of the full list.
    #[test]
    fn direct_dependences_imply_every_pair_and_keep_the_levels((reads, writes) in var_sets()) {
        let all = data_dependences_pairwise(&reads, &writes);
        let direct = direct_dependences(&reads, &writes);
        let mut sorted_all = all.clone();
        sorted_all.sort_unstable();
        for d in &direct {
            prop_assert!(sorted_all.binary_search(d).is_ok(), "{:?} is not a dependence", d);
        }
        let n = reads.len();
        // Reachability over the direct pairs (units are in order, so one forward pass each).
        let mut succ = vec![Vec::new(); n];
        for d in &direct {
            succ[d.from as usize].push(d.to as usize);
        }
        for s in 0..n {
            let mut reach = vec![false; n];
            reach[s] = true;
            for u in s..n {
                if reach[u] {
                    for &v in &succ[u] {
                        reach[v] = true;
                    }
                }
            }
            for d in all.iter().filter(|d| d.from as usize == s) {
                prop_assert!(reach[d.to as usize], "{:?} is not implied by the direct pairs", d);
            }
        }
        let edges: Vec<(u32, u32)> = direct.iter().map(|d| (d.from, d.to)).collect();
        prop_assert_eq!(data_levels(&reads, &writes), asap_levels(n, &edges));
        let c = dependence_counts(&reads, &writes);
        let of = |k: DepKind| all.iter().filter(|d| d.kind == k).count() as u64;
        prop_assert_eq!((c.flow, c.anti, c.output), (of(DepKind::Flow), of(DepKind::Anti), of(DepKind::Output)));
        let per_var: u64 = c.by_var.iter().map(|&(_, f, a, o)| f + a + o).sum();
        prop_assert_eq!(per_var, all.len() as u64);
    }
}

/// Post-dominator sets by the textbook fixpoint: pdom(STOP) = {STOP};
/// pdom(n) = {n} ∪ ⋂ pdom(s) over successors s.
fn brute_pdom(n: usize, edges: &[(u32, u32)], stop: usize) -> Vec<Vec<bool>> {
    let mut pd = vec![vec![true; n]; n];
    pd[stop] = (0..n).map(|i| i == stop).collect();
    loop {
        let mut changed = false;
        for v in 0..n {
            if v == stop {
                continue;
            }
            let mut set = vec![true; n];
            let mut any = false;
            for &(a, b) in edges {
                if a as usize == v {
                    any = true;
                    for i in 0..n {
                        set[i] &= pd[b as usize][i];
                    }
                }
            }
            if !any {
                set = vec![false; n];
            }
            set[v] = true;
            if set != pd[v] {
                pd[v] = set;
                changed = true;
            }
        }
        if !changed {
            return pd;
        }
    }
}

fn cfg() -> impl Strategy<Value = (usize, Vec<(u32, u32)>)> {
    // Nodes 0..n-1; n-1 is STOP; a chain keeps every node able to reach STOP.
    (3usize..24).prop_flat_map(|n| {
        proptest::collection::vec((0..n as u32 - 1, 0..n as u32), 0..2 * n).prop_map(move |extra| {
            let mut edges: Vec<(u32, u32)> = (0..n as u32 - 1).map(|i| (i, i + 1)).collect();
            edges.extend(extra);
            (n, edges)
        })
    })
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(2000))]

    #[test]
    fn post_dominators_and_control_dependences_match_their_definitions((n, edges) in cfg()) {
        let stop = n - 1;
        let pd = post_dominators(n, &edges, stop as u32);
        let sets = brute_pdom(n, &edges, stop);
        for a in 0..n {
            for b in 0..n {
                prop_assert_eq!(pd.post_dominates(a as u32, b as u32), sets[b][a], "pdom({}, {})", a, b);
            }
        }
        // Y is control dependent on X iff X has a successor S with Y pdom S, and Y does not
        // strictly post-dominate X.
        let mut want = std::collections::BTreeSet::new();
        for &(x, s) in &edges {
            for y in 0..n {
                if sets[s as usize][y] && !(sets[x as usize][y] && y != x as usize) {
                    want.insert((x, y as u32));
                }
            }
        }
        let got: std::collections::BTreeSet<(u32, u32)> =
            control_dependences(&edges, &pd, |_| true).iter().map(|d| (d.controller, d.dependent)).collect();
        prop_assert_eq!(got, want);
    }
}

/// Checks the combined schedule's safety conditions pairwise on one program.
fn check_schedule(text: &str) -> Result<bool, TestCaseError> {
    let Ok(p) = plc_deps::load::program_from_json(text) else {
        return Ok(false);
    };
    let a = analyse(&p);
    let s = &a.schedule;
    let task_acc: Vec<(Vec<VarId>, Vec<VarId>)> = s
        .tasks
        .iter()
        .map(|t| {
            let mut r: Vec<VarId> = t
                .rungs
                .iter()
                .flat_map(|&x| a.accesses.ins(x).iter().copied())
                .collect();
            let mut w: Vec<VarId> = t
                .rungs
                .iter()
                .flat_map(|&x| a.accesses.outs(x).iter().copied())
                .collect();
            r.sort();
            w.sort();
            (r, w)
        })
        .collect();
    let meets = |a: &[VarId], b: &[VarId]| a.iter().any(|x| b.binary_search(x).is_ok());
    for j in 0..s.tasks.len() {
        for i in 0..j {
            let (ri, wi) = &task_acc[i];
            let (rj, wj) = &task_acc[j];
            if meets(wi, rj) || meets(ri, wj) || meets(wi, wj) {
                prop_assert!(
                    s.tasks[i].level < s.tasks[j].level,
                    "tasks {:?} and {:?} conflict but are not ordered",
                    s.tasks[i].rungs,
                    s.tasks[j].rungs
                );
            }
        }
        for g in &s.tasks[j].guard {
            prop_assert!(s.task(g.controller).level < s.tasks[j].level);
        }
    }
    // Every main rung is in one task or unreachable; every CFG cycle of the main program stays
    // inside one task (no edge leads from a later task back to an earlier one).
    let main = p.main().rungs.clone();
    for r in main.clone() {
        let in_task = s.task_of[r as usize].is_some();
        let unreachable = s.unreachable.iter().any(|u| u.raw() == r);
        prop_assert!(in_task != unreachable);
    }
    for e in &a.cfg.edges {
        if main.contains(&e.from.raw()) && main.contains(&e.to.raw()) {
            if let (Some(x), Some(y)) = (
                s.task_of[e.from.raw() as usize],
                s.task_of[e.to.raw() as usize],
            ) {
                prop_assert!(
                    x <= y,
                    "edge {} → {} goes backwards between tasks",
                    e.from.raw(),
                    e.to.raw()
                );
            }
        }
    }
    // Levels are ASAP: every task above level 0 has a predecessor exactly one level below.
    for (t, task) in s.tasks.iter().enumerate() {
        if task.level > 0 {
            prop_assert!(s.preds[t]
                .iter()
                .any(|&q| s.task(q).level + 1 == task.level));
        }
    }
    Ok(true)
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(3000))]

    #[test]
    fn combined_schedule_is_safe_on_random_programs(seed in any::<u64>()) {
        let text = common::random_program(seed, 24);
        let loaded = check_schedule(&text)?;
        prop_assume!(loaded);
    }

    /// Listing every pair or only the direct ones changes nothing but the list.
    #[test]
    fn levels_and_schedule_do_not_depend_on_the_listing(seed in any::<u64>()) {
        let text = common::random_program(seed, 24);
        let Ok(p) = plc_deps::load::program_from_json(&text) else {
            return Err(TestCaseError::reject("not a valid program"));
        };
        let cfg = |dependences| AnalysisConfig { dependences };
        let all = analyse_with(&p, &cfg(DependenceListing::All));
        let direct = analyse_with(&p, &cfg(DependenceListing::Direct));
        prop_assert_eq!(all.listed, Listed::All);
        prop_assert_eq!(direct.listed, Listed::Direct);
        prop_assert_eq!(&all.data_levels, &direct.data_levels);
        prop_assert_eq!(&all.control_levels, &direct.control_levels);
        let tasks = |a: &plc_deps::analysis::Analysis| -> Vec<(Vec<u32>, u32)> {
            a.schedule.tasks.iter().map(|t| (t.rungs.iter().map(|r| r.raw()).collect(), t.level)).collect()
        };
        prop_assert_eq!(tasks(&all), tasks(&direct));
        prop_assert_eq!(&all.counts, &direct.counts);
        prop_assert!(direct.data.len() <= all.data.len());
        // UpTo picks all below the limit and direct above it.
        let total = all.counts.total();
        prop_assert_eq!(analyse_with(&p, &cfg(DependenceListing::UpTo(total))).listed, Listed::All);
        if total > 0 {
            prop_assert_eq!(analyse_with(&p, &cfg(DependenceListing::UpTo(total - 1))).listed, Listed::Direct);
        }
    }
}
