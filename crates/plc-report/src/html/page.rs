//! The HTML report's page skeleton: head with the inline style sheet, the summary section, the
//! legend, and the foot with the inline script that highlights a rung's dependences.
//!
//! The script indexes, once at load, every element with `data-rung` (cards, chips, Gantt bars,
//! CFG nodes, table rows) and every edge (`data-from`, `data-to`). Hovering a rung shows what it
//! depends on (class `dep`) and what depends on it (`user`), the rung itself `sel` and the edges
//! `hl`; a click pins that (a second click or Escape clears it), and the info line says it in
//! words. It is wrapped in a CDATA section so the page stays well-formed XML.
//!
//! Deliberately not here: any external resource (fonts, scripts, images), any state kept
//! between visits.

use super::{esc, thousands};
use crate::document::Report;
use crate::words::plural;
use std::io::{self, Write};

const STYLE: &str = r#"
body{font:13px/1.45 system-ui,-apple-system,"Segoe UI",sans-serif;margin:0 24px 90px;color:#1d1d1d;background:#f7f7f5}
h1{font-size:21px;margin:18px 0 4px}h2{font-size:16px;margin:30px 0 8px;padding-bottom:3px;border-bottom:1px solid #ccc}h3{font-size:13px;margin:12px 0 4px}
table{border-collapse:collapse;background:#fff}td,th{padding:3px 9px;text-align:left;border-bottom:1px solid #e5e5e5;vertical-align:top}th{background:#efefec}
code{background:#eee;padding:0 3px;border-radius:3px}
.note{color:#7a4b00;background:#fff6e0;border:1px solid #ecd9a8;padding:6px 10px;border-radius:4px}
.summary{display:flex;flex-wrap:wrap;gap:28px;align-items:flex-start}
.scroll{overflow:auto;max-height:88vh;border:1px solid #ddd;background:#fff}
svg text{font-family:ui-monospace,"DejaVu Sans Mono",Menlo,monospace;font-size:10px;fill:#222}
.levels .colhdr{font-size:12px;font-weight:bold;fill:#444}
.card{cursor:pointer}.card rect.frame{fill:#fff;stroke:#a8a8a8;stroke-width:1}
.card .hdr{font-size:11px;font-weight:bold}.card .meta{fill:#777}
.card.sel rect.frame{stroke:#111;stroke-width:3;fill:#fff6c2}
.card.dep rect.frame{stroke:#d35400;stroke-width:3;fill:#ffeedd}
.card.user rect.frame{stroke:#1f6fd1;stroke-width:3;fill:#e4efff}
.ld line,.ld path{stroke:#333;stroke-width:1.2;fill:none}.ld rect{fill:#f2f2ee;stroke:#444}
.loop{fill:none;stroke:#8e44ad;stroke-dasharray:5 3}.looplbl{fill:#8e44ad}
.e path{fill:none;stroke-width:1.3;opacity:.55}.e text{font-size:9px}
.e.flow path{stroke:#222}.e.anti path{stroke:#1f6fd1;stroke-dasharray:6 3}
.e.output path{stroke:#c0392b;stroke-dasharray:2 2}.e.control path{stroke:#1e8449;stroke-width:2}
.e.flow text{fill:#222}.e.anti text{fill:#1f6fd1}.e.output text{fill:#c0392b}.e.control text{fill:#1e8449}
.e.hl path{opacity:1;stroke-width:3.2}.e.hl text{font-weight:bold;font-size:11px}
.many .e text{display:none}.many .e.hl text{display:inline}
.active .e:not(.hl){opacity:.25}
.chip{display:inline-block;padding:0 5px;margin:1px;border:1px solid #bbb;border-radius:9px;background:#fff;cursor:pointer;font-family:ui-monospace,monospace;font-size:12px}
.chip.diff{border-color:#c0392b;background:#fdecea;color:#a02a1d;font-weight:bold}
.looptask{border:1px dashed #8e44ad;border-radius:10px;padding:1px 3px}
.chip.sel,.chip.dep,.chip.user{outline:2px solid #111}.chip.dep{background:#ffeedd}.chip.user{background:#e4efff}
tr.sel,tr.dep,tr.user{background:#fff6c2}
.bar.list{fill:#2e86c1}.bar.level{fill:#aab7b8}.bar.measured{fill:#d35400}.bar.ideal{fill:#7d3c98}.axis{stroke:#555}.axis.one{stroke-dasharray:3 3}
tr.this td{background:#fff6c2;font-weight:bold}
.sw{display:inline-block;width:12px;height:12px;vertical-align:-2px}.sw.list{background:#2e86c1}.sw.level{background:#aab7b8}
.legend .k{display:inline-block;width:26px;height:0;vertical-align:middle;margin:0 4px 0 12px;border-top:2px solid}
.k.flow{border-color:#222}.k.anti{border-top:2px dashed #1f6fd1}.k.output{border-top:2px dotted #c0392b}.k.control{border-top:3px solid #1e8449}
.gantt .slot rect{fill:#aed6f1;stroke:#2e86c1}.gantt .busy{fill:#aed6f1}.gantt .slot{cursor:pointer}
.gantt .slot.sel rect{fill:#f9e79f}.gantt .slot.dep rect{fill:#f5cba7}.gantt .slot.user rect{fill:#a9cce3}
.graphs{display:flex;flex-wrap:wrap;gap:24px;align-items:flex-start}figure{margin:0;background:#fff;border:1px solid #ddd;padding:8px;overflow:auto;max-width:100%}
.graph .node rect{fill:#fff;stroke:#555}.graph .node{cursor:pointer}
.graph .node.sel rect{fill:#fff6c2;stroke-width:3}.graph .node.dep rect{fill:#ffeedd}.graph .node.user rect{fill:#e4efff}
.graph polyline{fill:none;stroke:#555;stroke-width:1.2}.graph polyline.back{stroke-dasharray:4 3}
.graph .jump{stroke:#1f6fd1}.graph .call,.graph .return{stroke:#8e44ad}.graph .loop-back,.graph .loop-enter,.graph .loop-exit{stroke:#d35400}
.graph .tf{font-weight:bold;fill:#1e8449}
#info{position:fixed;left:0;right:0;bottom:0;padding:7px 24px;background:#1f2a33;color:#f4f4f4;font-size:13px;min-height:19px}
"#;

const SCRIPT: &str = r#"
(function () {
  var byRung = {}, into = {}, outOf = {}, pinned = null;
  function add(map, k, v) { (map[k] = map[k] || []).push(v); }
  Array.prototype.forEach.call(document.querySelectorAll('[data-rung]'), function (e) {
    add(byRung, e.getAttribute('data-rung'), e);
  });
  Array.prototype.forEach.call(document.querySelectorAll('.e[data-from]'), function (e) {
    add(outOf, e.getAttribute('data-from'), e);
    add(into, e.getAttribute('data-to'), e);
  });
  var info = document.getElementById('info');
  if (!info) { return; } // a summarised page draws no rung to hover
  var idle = info.textContent;
  var marked = [];
  function mark(list, cls) {
    (list || []).forEach(function (e) { e.classList.add(cls); marked.push([e, cls]); });
  }
  function clear() {
    marked.forEach(function (m) { m[0].classList.remove(m[1]); });
    marked = [];
    Array.prototype.forEach.call(document.querySelectorAll('svg.levels'), function (s) { s.classList.remove('active'); });
    info.textContent = idle;
  }
  function words(edges, end) {
    return edges.map(function (e) {
      var k = e.getAttribute('class').split(' ')[1];
      return e.getAttribute(end) + ' (' + k + ' ' + e.getAttribute('data-var') + ')';
    }).join(', ');
  }
  function show(id) {
    clear();
    var ins = into[id] || [], outs = outOf[id] || [];
    mark(byRung[id], 'sel');
    ins.forEach(function (e) { mark([e], 'hl'); mark(byRung[e.getAttribute('data-from')], 'dep'); });
    outs.forEach(function (e) { mark([e], 'hl'); mark(byRung[e.getAttribute('data-to')], 'user'); });
    Array.prototype.forEach.call(document.querySelectorAll('svg.levels'), function (s) { s.classList.add('active'); });
    info.textContent = id + ' depends on ' + (ins.length ? words(ins, 'data-from') : 'nothing') +
      '; depending on it: ' + (outs.length ? words(outs, 'data-to') : 'nothing') +
      (pinned ? '  (click again or Esc to clear)' : '');
  }
  function rungOf(t) {
    var e = t.closest ? t.closest('[data-rung]') : null;
    return e ? e.getAttribute('data-rung') : null;
  }
  document.addEventListener('mouseover', function (ev) {
    var id = rungOf(ev.target);
    if (pinned === null) { if (id === null) { clear(); } else { show(id); } }
  });
  document.addEventListener('click', function (ev) {
    var id = rungOf(ev.target);
    if (id === null || id === pinned) { pinned = null; clear(); return; }
    pinned = id;
    show(id);
    var card = document.getElementById('rung-' + id);
    if (card && !card.contains(ev.target) && card.scrollIntoView) {
      card.scrollIntoView({block: 'center', inline: 'center'});
    }
  });
  document.addEventListener('keydown', function (ev) {
    if (ev.key === 'Escape') { pinned = null; clear(); }
  });
})();
"#;

/// Writes the doctype, the head with the style sheet, the shared SVG definitions and the title.
/// `command` is the command the page is of (`report`, `run`), for the title.
pub(super) fn write_head(out: &mut impl Write, program: &str, command: &str) -> io::Result<()> {
    writeln!(
        out,
        "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\"/>\n<meta name=\"viewport\" content=\"width=device-width, initial-scale=1\"/>\n<meta name=\"generator\" content=\"plc-deps {}\"/>\n<title>{} — plc-deps {command}</title>\n<style>{STYLE}</style>\n</head>\n<body>",
        env!("CARGO_PKG_VERSION"),
        esc(program)
    )?;
    out.write_all(b"<svg width=\"0\" height=\"0\" style=\"position:absolute\" aria-hidden=\"true\"><defs><marker id=\"arrow\" viewBox=\"0 0 10 10\" refX=\"10\" refY=\"5\" markerWidth=\"7\" markerHeight=\"7\" orient=\"auto-start-reverse\"><path d=\"M0 0L10 5L0 10z\" fill=\"#555\"/></marker></defs></svg>\n")?;
    writeln!(
        out,
        "<h1>{} <small>— dependence analysis and levelling (plc-deps)</small></h1>",
        esc(program)
    )
}

fn saved(before: usize, after: usize) -> String {
    if before == 0 {
        return String::new();
    }
    crate::words::saved_percent(before, after)
}

/// Writes the summary: sizes, scan cycles per view, cost figures, makespan bars, warnings.
pub(super) fn write_summary(out: &mut impl Write, r: &Report) -> io::Result<()> {
    out.write_all(b"<section id=\"summary\">\n")?;
    let mut size = format!(
        "{} ({} in the main program, {} in subroutines)",
        plural(r.summary.rungs, "rung", "rungs"),
        thousands(r.summary.main_rungs),
        thousands(r.summary.rungs - r.summary.main_rungs)
    );
    if let Some(f) = &r.fbd {
        size.push_str(&format!(
            "; written as {} in {}",
            plural(f.blocks, "FBD block", "FBD blocks"),
            plural(f.networks, "network", "networks")
        ));
    }
    writeln!(out, "<p>{size}.</p>\n<div class=\"summary\">")?;
    let c = &r.cycles;
    out.write_all(
        b"<table class=\"cycles\"><tr><th>schedule</th><th>scan cycles</th><th>saved</th></tr>\n",
    )?;
    for (name, n) in [
        ("sequential (one rung per cycle)", c.before),
        ("paper data view", c.data),
        ("paper control view", c.control),
        ("combined (correct)", c.combined),
    ] {
        let s = if n == c.before && name.starts_with("seq") {
            String::new()
        } else {
            saved(c.before, n)
        };
        writeln!(
            out,
            "<tr><td>{name}</td><td>{}</td><td>{s}</td></tr>",
            thousands(n)
        )?;
    }
    out.write_all(b"</table>\n<div>\n")?;
    writeln!(
        out,
        "<p>work W = {}, span S = {}, ideal speed-up W/S = {:.2}</p>",
        r.cost.work, r.cost.span, r.cost.ideal_speedup
    )?;
    super::charts::write_bars(out, r)?;
    out.write_all(b"</div>\n</div>\n")?;
    write_warnings(
        out,
        r.warning_codes
            .iter()
            .copied()
            .zip(r.warnings.iter().map(String::as_str)),
    )?;
    out.write_all(b"</section>\n")
}

/// A list of warnings, `(code, message)` each (nothing when there are none).
pub(super) fn write_warnings<'w>(
    out: &mut impl Write,
    warnings: impl Iterator<Item = (&'w str, &'w str)>,
) -> io::Result<()> {
    let mut warnings = warnings.peekable();
    if warnings.peek().is_none() {
        return Ok(());
    }
    out.write_all(b"<ul class=\"warnings\">\n")?;
    for (code, w) in warnings {
        writeln!(out, "<li class=\"note\">warning[{code}]: {}</li>", esc(w))?;
    }
    out.write_all(b"</ul>\n")
}

/// The legend of the level view.
pub(super) fn write_level_legend(out: &mut impl Write) -> io::Result<()> {
    out.write_all(b"<p class=\"legend\">Columns are levels (rungs of one level may run at the same time). Edges: <span class=\"k flow\"></span>flow <span class=\"k anti\"></span>anti <span class=\"k output\"></span>output <span class=\"k control\"></span>control (the paper's). Hover or click a rung: <b>its dependences</b> in orange, what depends on it in blue.</p>\n")
}

/// The info line (where rungs are drawn as cards to hover), the script and the end of the page.
pub(super) fn write_foot(out: &mut impl Write, cards: bool) -> io::Result<()> {
    out.write_all(b"<p class=\"legend\">Made by plc-deps; the definitions and the cost model are in its docs/report.md, this page in docs/html.md.</p>\n")?;
    if cards {
        out.write_all(b"<div id=\"info\">Hover or click a rung to see what it depends on and what depends on it.</div>\n")?;
    }
    writeln!(
        out,
        "<script>//<![CDATA[{SCRIPT}//]]></script>\n</body>\n</html>"
    )
}
