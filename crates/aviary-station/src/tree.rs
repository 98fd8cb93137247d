//! The mission's block tree as the page shows it: blocks, the activities their statements
//! start, handlers and what else a body does, with the names the trace uses, so that the
//! page can give each node the live status the trace's events say (a block by its
//! `block` name, a statement by its `line`, a handler by its `handler` name).

use aviary_diagnostics::SourceMap;
use aviary_ir::{ActorFilter, ActorRef, Block, BlockKind, Mission, Node, Origin};
use serde_json::{json, Value};

/// The tree of `mission`'s body; nodes carry their line when `sources` can say it.
pub fn of(mission: &Mission, sources: Option<&SourceMap>) -> Value {
    Tree { m: mission, sources }.block(&mission.body, "block")
}

struct Tree<'a> {
    m: &'a Mission,
    sources: Option<&'a SourceMap>,
}

impl Tree<'_> {
    /// The node's line, as the trace's events name it (`Mission::line_of`): what the page
    /// follows each statement by.
    fn line(&self, origin: &Origin) -> Value {
        match (self.m.line_of(origin), self.sources) {
            (Some(line), _) => line.into(),
            (None, Some(s)) => s.line_col(origin.file, origin.span.start).line.into(),
            (None, None) => Value::Null,
        }
    }

    fn drones(&self, actor: &ActorRef) -> Value {
        match actor {
            ActorRef::Drone(d) => json!([self.m.drones.get(*d)]),
            ActorRef::Group(ds) => ds.iter().map(|d| self.m.drones.get(*d)).collect(),
            // An alias or a parameter: whichever drone it stands for at run time.
            ActorRef::Slot(_) => Value::Null,
        }
    }

    fn block(&self, b: &Block, kind: &str) -> Value {
        let mut children: Vec<Value> = Vec::new();
        for node in &b.items {
            if let Some(v) = self.node(node) {
                children.push(v);
            }
        }
        for h in &b.handlers {
            let by = match &h.by {
                Some(ActorFilter::Drones(ds)) => ds.iter().map(|d| self.m.drones.get(*d)).collect(),
                _ => Value::Null,
            };
            let mut v = self.block(&h.body, "handler");
            v["signal"] = self.m.signals.get(h.signal).cloned().into();
            v["by"] = by;
            children.push(v);
        }
        for h in &b.exception_handlers {
            let mut v = self.block(&h.body, "exception_handler");
            v["exception"] = self.m.exceptions.get(h.exception).cloned().into();
            children.push(v);
        }
        json!({
            "kind": kind,
            "name": b.path,
            "traced": b.traced,
            "parallel": b.kind == BlockKind::Parallel,
            "children": children,
        })
    }

    fn node(&self, node: &Node) -> Option<Value> {
        Some(match node {
            Node::Block(b) => self.block(b, "block"),
            Node::Call(c) => {
                let actors: Vec<Value> = c.actors.iter().map(|a| self.drones(a)).collect();
                json!({
                    "kind": "activity",
                    "capability": self.m.capabilities.get(c.capability).map(|c| c.name.as_str()),
                    "tag": c.tag.and_then(|t| self.m.tags.get(t)),
                    "actors": actors,
                    "line": self.line(&c.origin),
                })
            }
            Node::Leash(l) => json!({
                "kind": "leash",
                "capability": self.m.capabilities.get(l.capability).map(|c| c.name.as_str()),
                "tag": self.m.tags.get(l.tag),
                "action": l.action_name,
                "line": self.line(&l.origin),
            }),
            Node::StopBlock { block, origin } => json!({
                "kind": "leash",
                "block": block,
                "action": "ABORT",
                "line": self.line(origin),
            }),
            Node::Signal { signal, origin, .. } => json!({
                "kind": "signal",
                "signal": self.m.signals.get(*signal),
                "line": self.line(origin),
            }),
            Node::Throw { exception, origin, .. } => json!({
                "kind": "throw",
                "exception": self.m.exceptions.get(*exception),
                "line": self.line(origin),
            }),
            Node::StartIf { body, .. } => self.wrapped("start_if", body),
            Node::WaitFor { body: Some(body), .. } => self.wrapped("waitfor", body),
            Node::WaitFor { body: None, .. } => json!({ "kind": "waitfor", "children": [] }),
            Node::DoWhile { body, .. } => self.wrapped("dowhile", body),
            Node::For(f) => {
                let mut v = self.wrapped("for", &f.body);
                v["parallel"] = f.parallel.into();
                v["instances"] = f.instances.len().into();
                v
            }
            Node::Any(a) => {
                let mut v = self.wrapped("any", &a.body);
                v["group"] = a.group.as_str().into();
                v["count"] = a.count.into();
                v["line"] = self.line(&a.origin);
                v
            }
            Node::If { branches, otherwise } => {
                let mut children: Vec<Value> =
                    branches.iter().map(|(_, b)| self.wrapped("branch", b)).collect();
                if let Some(b) = otherwise {
                    children.push(self.wrapped("otherwise", b));
                }
                json!({ "kind": "if", "children": children })
            }
            // A middle-layer call is written only inside capabilities.
            // A value taken, not work: the tree shows what runs.
            Node::Api(_) | Node::Let { .. } => return None,
        })
    }

    /// A construct around a body: the body's own node, when it is a traced block, or its
    /// items.
    fn wrapped(&self, kind: &str, body: &Block) -> Value {
        let inner = self.block(body, "block");
        match body.traced {
            true => json!({ "kind": kind, "children": [inner] }),
            false => json!({ "kind": kind, "children": inner["children"].clone() }),
        }
    }
}
