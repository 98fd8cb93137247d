//! The mission's block tree as the page shows it: blocks, the activities their statements
//! start, handlers and what else a body does, with the names the trace uses, so that the
//! page can give each node the live status the trace's events say (a block by its
//! `block` name, a statement by its `line`, a handler by its `handler` name).

use aviary_diagnostics::SourceMap;
use aviary_ir::{ActorFilter, ActorRef, Block, BlockKind, Mission, Node, Origin};
use serde::Serialize;
use serde_json::Value;

/// The tree of `mission`'s body; nodes carry their line when `sources` can say it.
pub fn of(mission: &Mission, sources: Option<&SourceMap>) -> Value {
    serde_json::to_value(typed(mission, sources)).unwrap_or(Value::Null)
}

/// The tree of `mission`'s body, typed.
pub fn typed<'m>(mission: &'m Mission, sources: Option<&SourceMap>) -> TreeNode<'m> {
    TreeNode::Block(Tree { m: mission, sources }.block(&mission.body))
}

/// A node of the tree, by its `kind`.
#[derive(Debug, Serialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum TreeNode<'m> {
    Block(BlockNode<'m>),
    /// A signal's handler: its body, the signal, and the drones it listens to (`null`:
    /// any).
    Handler {
        #[serde(flatten)]
        body: BlockNode<'m>,
        signal: Option<&'m str>,
        by: Option<Vec<Option<&'m str>>>,
    },
    ExceptionHandler {
        #[serde(flatten)]
        body: BlockNode<'m>,
        exception: Option<&'m str>,
    },
    /// A capability's activity: its drones, one list (`null`: whichever drone a name
    /// stands for at run time) per actor.
    Activity {
        capability: Option<&'m str>,
        tag: Option<&'m str>,
        actors: Vec<Option<Vec<Option<&'m str>>>>,
        line: Option<usize>,
    },
    Leash(Leash<'m>),
    Signal {
        signal: Option<&'m str>,
        line: Option<usize>,
    },
    Throw {
        exception: Option<&'m str>,
        line: Option<usize>,
    },
    StartIf(Wrapped<'m>),
    Waitfor(Wrapped<'m>),
    Dowhile(Wrapped<'m>),
    For {
        #[serde(flatten)]
        body: Wrapped<'m>,
        parallel: bool,
        instances: usize,
    },
    Any {
        #[serde(flatten)]
        body: Wrapped<'m>,
        group: &'m str,
        count: usize,
        line: Option<usize>,
    },
    Branch(Wrapped<'m>),
    Otherwise(Wrapped<'m>),
    If(Wrapped<'m>),
}

/// A block: its name as the trace's events give it, and what it does.
#[derive(Debug, Serialize)]
pub struct BlockNode<'m> {
    pub name: &'m str,
    pub traced: bool,
    pub parallel: bool,
    pub children: Vec<TreeNode<'m>>,
}

/// A leash on a tagged activity, or the ABORT of a block.
#[derive(Debug, Serialize)]
#[serde(untagged)]
pub enum Leash<'m> {
    Activity {
        capability: Option<&'m str>,
        tag: Option<&'m str>,
        action: &'m str,
        line: Option<usize>,
    },
    Block {
        block: &'m str,
        action: &'m str,
        line: Option<usize>,
    },
}

/// A construct around a body: what it holds.
#[derive(Debug, Serialize)]
pub struct Wrapped<'m> {
    pub children: Vec<TreeNode<'m>>,
}

struct Tree<'m, 's> {
    m: &'m Mission,
    sources: Option<&'s SourceMap>,
}

impl<'m> Tree<'m, '_> {
    /// The node's line, as the trace's events name it (`Mission::line_of`): what the page
    /// follows each statement by.
    fn line(&self, origin: &Origin) -> Option<usize> {
        match (self.m.line_of(origin), self.sources) {
            (Some(line), _) => Some(line as usize),
            (None, Some(s)) => Some(s.line_col(origin.file, origin.span.start).line),
            (None, None) => None,
        }
    }

    fn drones(&self, actor: &ActorRef) -> Option<Vec<Option<&'m str>>> {
        match actor {
            ActorRef::Drone(d) => Some(vec![self.m.drones.get(*d)]),
            ActorRef::Group(ds) => Some(ds.iter().map(|d| self.m.drones.get(*d)).collect()),
            // An alias or a parameter: whichever drone it stands for at run time.
            ActorRef::Slot(_) => None,
        }
    }

    fn block(&self, b: &'m Block) -> BlockNode<'m> {
        let mut children: Vec<TreeNode<'m>> = Vec::new();
        for node in &b.items {
            if let Some(v) = self.node(node) {
                children.push(v);
            }
        }
        for h in &b.handlers {
            let by = match &h.by {
                Some(ActorFilter::Drones(ds)) => {
                    Some(ds.iter().map(|d| self.m.drones.get(*d)).collect())
                }
                _ => None,
            };
            children.push(TreeNode::Handler {
                body: self.block(&h.body),
                signal: self.m.signals.get(h.signal).map(String::as_str),
                by,
            });
        }
        for h in &b.exception_handlers {
            children.push(TreeNode::ExceptionHandler {
                body: self.block(&h.body),
                exception: self.m.exceptions.get(h.exception).map(String::as_str),
            });
        }
        BlockNode {
            name: &b.path,
            traced: b.traced,
            parallel: b.kind == BlockKind::Parallel,
            children,
        }
    }

    fn capability(&self, id: aviary_ir::CapId) -> Option<&'m str> {
        self.m.capabilities.get(id).map(|c| c.name.as_str())
    }

    fn node(&self, node: &'m Node) -> Option<TreeNode<'m>> {
        let tag = |t| self.m.tags.get(t).map(String::as_str);
        Some(match node {
            Node::Block(b) => TreeNode::Block(self.block(b)),
            Node::Call(c) => TreeNode::Activity {
                capability: self.capability(c.capability),
                tag: c.tag.and_then(tag),
                actors: c.actors.iter().map(|a| self.drones(a)).collect(),
                line: self.line(&c.origin),
            },
            Node::Leash(l) => TreeNode::Leash(Leash::Activity {
                capability: self.capability(l.capability),
                tag: tag(l.tag),
                action: self
                    .m
                    .capabilities
                    .get(l.capability)
                    .and_then(|c| c.action_name(l.action))
                    .unwrap_or_default(),
                line: self.line(&l.origin),
            }),
            Node::StopBlock { block, origin } => {
                TreeNode::Leash(Leash::Block { block, action: "ABORT", line: self.line(origin) })
            }
            Node::Signal { signal, origin, .. } => TreeNode::Signal {
                signal: self.m.signals.get(*signal).map(String::as_str),
                line: self.line(origin),
            },
            Node::Throw { exception, origin, .. } => TreeNode::Throw {
                exception: self.m.exceptions.get(*exception).map(String::as_str),
                line: self.line(origin),
            },
            Node::StartIf { body, .. } => TreeNode::StartIf(self.wrapped(body)),
            Node::WaitFor { body: Some(body), .. } => TreeNode::Waitfor(self.wrapped(body)),
            Node::WaitFor { body: None, .. } => TreeNode::Waitfor(Wrapped { children: Vec::new() }),
            Node::DoWhile { body, .. } => TreeNode::Dowhile(self.wrapped(body)),
            Node::For(f) => TreeNode::For {
                body: self.wrapped(&f.body),
                parallel: f.parallel,
                instances: f.instances.len(),
            },
            Node::Any(a) => TreeNode::Any {
                body: self.wrapped(&a.body),
                group: a.group.as_str(),
                count: a.count,
                line: self.line(&a.origin),
            },
            Node::If { branches, otherwise } => {
                let mut children: Vec<TreeNode<'m>> =
                    branches.iter().map(|(_, b)| TreeNode::Branch(self.wrapped(b))).collect();
                if let Some(b) = otherwise {
                    children.push(TreeNode::Otherwise(self.wrapped(b)));
                }
                TreeNode::If(Wrapped { children })
            }
            // A middle-layer call is written only inside capabilities.
            // A value taken, not work: the tree shows what runs.
            Node::Api(_) | Node::Let { .. } => return None,
        })
    }

    /// A construct around a body: the body's own node, when it is a traced block, or its
    /// items.
    fn wrapped(&self, body: &'m Block) -> Wrapped<'m> {
        let inner = self.block(body);
        match body.traced {
            true => Wrapped { children: vec![TreeNode::Block(inner)] },
            false => Wrapped { children: inner.children },
        }
    }
}
