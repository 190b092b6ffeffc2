//! Export of the tree and its abstraction as a Promela model, so the SPIN model checker
//! can check the same properties independently of betr's own explorer.
//!
//! One `bool` per relevant atom; one `d_step` per abstract tick that evaluates the tree
//! with the reactive semantics (a status per node: 0 failure, 1 success, 2 running) and
//! applies the first reached action's declared effects. Nondeterminism is chosen between
//! ticks, outside the `d_step`s, so SPIN's claims only ever see whole ticks:
//!
//! * with action failures, how many of the actions reached in the next tick fail
//!   (`nfail`; the reached actions fail in tick order, leaving the state unchanged);
//! * each grounded disturbance whose guard holds;
//! * `calm`: from now on, no more failures or disturbances. betr's "reaches Success from
//!   every reachable state" means: from every state the runs can reach, the tree left
//!   alone succeeds. In LTL that is `[] (calm -> <> success)` (with nothing
//!   nondeterministic, `calm` is true from the start and the claim is `<> success`).
//!
//! Claims: `success`, `preconditions` (`[] !pre_violation`) and `p0`, `p1`, ... for the
//! user properties (`[] F`, `[] !F`, `<> F`). The process never ends: a success or a dead
//! end ticks forever without changing anything, as the reactive tree would.

use std::fmt::Write as _;

use super::PropertyKind;
use super::abstraction::{CNode, Expr, Model};
use super::temporal::Temporal;

/// A Promela model and the names of its `ltl` claims.
#[derive(Debug, Clone, PartialEq)]
pub struct PromelaModel {
    pub text: String,
    pub claims: Vec<(String, PropertyKind)>,
}

/// Export `model`; `user` gives the operator of each of `model.properties`.
pub fn export(model: &Model, user: &[Temporal], action_failures: bool) -> PromelaModel {
    let mut out = String::new();
    let nondeterministic = action_failures || !model.disturbances.is_empty();
    let _ = writeln!(
        out,
        "/* betr verify: a behavior tree and its abstraction (see src/verify/promela.rs).\n   {} atoms, {} nodes, {} actions, {} disturbance groundings, action failures {}. */\n",
        model.atoms.len(),
        model.nodes.len(),
        model.actions.len(),
        model.disturbances.len(),
        if action_failures { "on" } else { "off" }
    );
    for (i, atom) in model.atoms.iter().enumerate() {
        let on = u8::from(super::abstraction::bit(&model.initial, i));
        let _ = writeln!(
            out,
            "bool f{i} = {on}; /* {} */",
            comment(&atom.to_string())
        );
    }
    let _ = writeln!(
        out,
        "\nbyte st[{}];       /* per node: 0 failure, 1 success, 2 running */",
        model.nodes.len().max(1)
    );
    let _ = writeln!(
        out,
        "bool success = 0;  /* the last tick: root Success, no action reached */"
    );
    let _ = writeln!(
        out,
        "bool pre_violation = 0; /* the last tick started an action whose declared precondition did not hold */"
    );
    let _ = writeln!(out, "bool reached = 0;");
    let _ = writeln!(
        out,
        "bool calm = {}; /* no more failures or disturbances */",
        u8::from(!nondeterministic)
    );
    let _ = writeln!(out, "byte nfail = 0;\n");

    let _ = writeln!(out, "inline tick() {{");
    let _ = writeln!(out, "  d_step {{");
    let _ = writeln!(out, "    reached = 0; pre_violation = 0;");
    node_code(model, 0, 2, &mut out);
    let _ = writeln!(
        out,
        "    success = (st[0] == 1 && !reached);\n    nfail = 0\n  }}\n}}\n"
    );

    let _ = writeln!(out, "active proctype betr() {{\n  do\n  :: tick()");
    if action_failures {
        for k in 1..=model.actions.len().min(255) {
            let _ = writeln!(out, "  :: !calm -> nfail = {k}; tick()");
        }
    }
    for d in &model.disturbances {
        let guard = if d.pre.is_empty() {
            String::new()
        } else {
            let parts: Vec<String> = d.pre.iter().map(|&c| cond(model, c)).collect();
            format!(" && {}", parts.join(" && "))
        };
        let _ = writeln!(
            out,
            "  :: !calm{guard} -> /* {} */\n     d_step {{ {}success = 0; pre_violation = 0 }}",
            comment(&format!("{} {}", d.description, d.grounding)),
            effects(&d.add, &d.del)
        );
    }
    if nondeterministic {
        let _ = writeln!(out, "  :: !calm -> calm = 1");
    }
    let _ = writeln!(out, "  od\n}}\n");

    let mut claims = vec![
        ("success".to_string(), PropertyKind::Success),
        ("preconditions".to_string(), PropertyKind::Preconditions),
    ];
    let _ = writeln!(out, "ltl success {{ [] (calm -> <> success) }}");
    let _ = writeln!(out, "ltl preconditions {{ [] !pre_violation }}");
    for (i, (e, t)) in model.properties.iter().zip(user).enumerate() {
        let f = expr(model, e);
        let body = match t {
            Temporal::Always => format!("[] {f}"),
            Temporal::Never => format!("[] !{f}"),
            Temporal::Eventually => format!("<> {f}"),
        };
        let _ = writeln!(out, "ltl p{i} {{ {body} }}");
        claims.push((format!("p{i}"), PropertyKind::User(i)));
    }
    PromelaModel { text: out, claims }
}

fn comment(text: &str) -> String {
    text.replace("*/", "* /")
}

fn effects(add: &[usize], del: &[usize]) -> String {
    let mut s = String::new();
    for i in del {
        let _ = write!(s, "f{i} = 0; ");
    }
    for i in add {
        let _ = write!(s, "f{i} = 1; ");
    }
    s
}

/// A condition as a Promela expression.
fn cond(model: &Model, c: usize) -> String {
    let bits = model.conditions[c].bits();
    let positive = match bits {
        [] => "false".to_string(),
        [one] => format!("f{one}"),
        many => format!(
            "({})",
            many.iter()
                .map(|i| format!("f{i}"))
                .collect::<Vec<_>>()
                .join(" || ")
        ),
    };
    if model.conditions[c].condition.negated {
        format!("!{positive}")
    } else {
        positive
    }
}

fn expr(model: &Model, e: &Expr) -> String {
    match e {
        Expr::Atom(c) => cond(model, *c),
        Expr::Not(x) => format!("!{}", expr(model, x)),
        Expr::And(v) if v.is_empty() => "true".into(),
        Expr::Or(v) if v.is_empty() => "false".into(),
        Expr::And(v) => format!(
            "({})",
            v.iter()
                .map(|x| expr(model, x))
                .collect::<Vec<_>>()
                .join(" && ")
        ),
        Expr::Or(v) => format!(
            "({})",
            v.iter()
                .map(|x| expr(model, x))
                .collect::<Vec<_>>()
                .join(" || ")
        ),
    }
}

/// The code of node `n`: sets `st[n]`. Composites tick a child only while the result so
/// far lets them continue (a Sequence while all succeeded, a Fallback while all failed).
fn node_code(model: &Model, n: usize, depth: usize, out: &mut String) {
    let pad = "  ".repeat(depth);
    match &model.nodes[n] {
        CNode::Sequence(children) | CNode::Fallback(children) => {
            let (start, go) = match &model.nodes[n] {
                CNode::Sequence(_) => (1, 1),
                _ => (0, 0),
            };
            let _ = writeln!(out, "{pad}st[{n}] = {start};");
            for &c in children {
                let _ = writeln!(out, "{pad}if\n{pad}:: st[{n}] == {go} ->");
                node_code(model, c, depth + 1, out);
                let _ = writeln!(
                    out,
                    "{pad}   st[{n}] = st[{c}]\n{pad}:: else -> skip\n{pad}fi;"
                );
            }
        }
        CNode::Condition(c) => {
            let _ = writeln!(
                out,
                "{pad}st[{n}] = ({} -> 1 : 0); /* {} */",
                cond(model, *c),
                comment(&model.conditions[*c].condition.to_string())
            );
        }
        CNode::Action(a) => {
            let action = &model.actions[*a];
            let _ = writeln!(out, "{pad}/* {}! */", comment(&action.call.to_string()));
            let _ = writeln!(out, "{pad}reached = 1;");
            if !action.pre.is_empty() {
                let pre: Vec<String> = action.pre.iter().map(|&c| cond(model, c)).collect();
                let _ = writeln!(
                    out,
                    "{pad}if :: !({}) -> pre_violation = 1 :: else -> skip fi;",
                    pre.join(" && ")
                );
            }
            let _ = writeln!(
                out,
                "{pad}if\n{pad}:: nfail > 0 -> nfail = nfail - 1; st[{n}] = 0\n{pad}:: else -> {}st[{n}] = 2\n{pad}fi;",
                effects(&action.add, &action.del)
            );
        }
    }
}
