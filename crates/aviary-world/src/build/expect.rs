//! `[expect]`: what success means for this mission in this world, beyond "no unhandled
//! exception" (docs/CAMPAIGNS.md): `aviary test` counts how many runs meet each, and
//! `aviary run` says which one a run did not meet.

use crate::node::{Node, Value};
use crate::read::{quoted, Ctx};
use crate::{Expectation, Target};

const EXPECT_KEYS: &[&str] = &["all_found", "min_found", "max_time", "min_battery"];
const HELP: &str = "write `[expect]` followed by lines such as `all_found = true`, `max_time = 1200` (seconds) and `min_battery = 0.25`";

/// The expectations of `[expect]`, in file order.
pub(super) fn expectations(cx: &mut Ctx, node: &Node, targets: &[Target]) -> Vec<Expectation> {
    let Some(entries) = cx.table(&"`expect`", node, HELP) else {
        return Vec::new();
    };
    cx.known_keys(entries, EXPECT_KEYS, "[expect]");
    let mut out = Vec::new();
    for e in entries {
        let n = &e.node;
        let expectation = match e.key.as_str() {
            "all_found" => match n.value {
                Value::Bool(true) if targets.is_empty() => {
                    cx.error(
                        n.span,
                        "`all_found` expects every target found, but the world has no `[[targets]]`",
                        "add the targets to find as `[[targets]]`, or remove `all_found`",
                    );
                    None
                }
                Value::Bool(true) => Some(Expectation::AllFound),
                // `false` expects nothing: written to say so, it is allowed.
                Value::Bool(false) => None,
                _ => {
                    let msg = format!("`all_found` must be true or false, found {}", n.describe());
                    cx.error(n.span, msg, "write `all_found = true`");
                    None
                }
            },
            "min_found" => match n.value {
                Value::Int(k) if k < 0 => {
                    let msg = format!("`min_found` must be zero or more targets, found {k}");
                    cx.error(
                        n.span,
                        msg,
                        "write how many targets must be found, e.g. `min_found = 2`",
                    );
                    None
                }
                Value::Int(k) if k as u64 > targets.len() as u64 => {
                    let msg = format!(
                        "`min_found` expects {k} targets found, but the world has {}",
                        crate::read::count(targets.len(), "target")
                    );
                    cx.error(
                        n.span,
                        msg,
                        "expect at most as many finds as there are `[[targets]]`",
                    );
                    None
                }
                Value::Int(k) => Some(Expectation::MinFound(k as u64)),
                _ => {
                    let msg = format!("`min_found` must be a whole number, found {}", n.describe());
                    cx.error(
                        n.span,
                        msg,
                        "write how many targets must be found, e.g. `min_found = 2`",
                    );
                    None
                }
            },
            "max_time" => {
                cx.positive(&"`max_time` (seconds) in [expect]", n).map(Expectation::MaxTime)
            }
            "min_battery" => cx
                .within(&"`min_battery` (a fraction of a full battery) in [expect]", n, 0.0, 1.0)
                .map(Expectation::MinBattery),
            // Reported by `known_keys`.
            _ => None,
        };
        out.extend(expectation);
    }
    if entries.is_empty() {
        let at = cx.header(node.span);
        cx.error(
            at,
            "`[expect]` expects nothing",
            format!("add one of {}, or remove the table", quoted(EXPECT_KEYS)),
        );
    }
    out
}
