fn main() {
    let path = std::env::args().nth(1).unwrap();
    let p = plc_deps::read::program_from_json(&std::fs::read_to_string(path).unwrap()).unwrap();
    let a = plc_deps::analysis::analyse(&p);
    let name = |r: u32| if (r as usize) < p.rungs.len() { p.rungs[r as usize].id.clone() } else if r as usize == p.rungs.len() { "START".into() } else { "STOP".into() };
    for d in &a.data { println!("{} {:?} {} {}", name(d.from), d.kind, name(d.to), p.var(d.var).name); }
    println!("data levels {:?}", a.data_levels);
    for n in 0..a.cfg.node_count() as u32 { print!("{}→{:?} ", name(n), a.post_dominators.immediate(n).map(name)); } println!();
    for d in &a.paper_control { println!("{} δc {} {:?}", p.rung(d.from).id, p.rung(d.to).id, d.cause); }
    println!("control levels {:?}", a.control_levels);
    for (l, ts) in a.schedule.levels.iter().enumerate() { println!("L{} {:?}", l+1, ts.iter().map(|&t| a.schedule.tasks[t as usize].rungs.iter().map(|r| p.rung(*r).id.clone()).collect::<Vec<_>>()).collect::<Vec<_>>()); }
    println!("{:?} {:?}", a.cost, a.warnings);
}
