// The mission's block tree, with the live status of every node: waiting, running, paused,
// done, aborted or failed, from the trace's events.
//
// Each statement is followed by its own identity: the trace names the line of every
// statement of the mission's file that an event is about (an activity's start and end, a
// SIGNAL, a leash, a THROW), and the tree's nodes carry their line. Blocks and handlers
// go by the names the trace gives them. What no event names is told by what it holds
// and where it stands:
// - a construct around a body (FOR, IF, STARTIF, WAITFOR, DOWHILE, ANY) by the statements
//   in it: running while one runs, finished when what ran of it has finished;
// - in a body that runs its items one after another, an item is over once a later one
//   has started (a WAITFOR that waited, an IF that chose nothing);
// - once a block or a handler is over, so is everything in it: what never ran stays
//   waiting (grey), which is what it did.

import { activityStatus, statementStatus } from "./model.js";

const FINISHED = ["done", "aborted", "failed"];

export class TreeView {
  constructor(element) {
    this.element = element;
    this.root = null;
  }

  show(tree) {
    this.element.textContent = "";
    this.root = null;
    if (!tree) {
      this.element.textContent = "no mission yet";
      return;
    }
    const ul = document.createElement("ul");
    const { li, entry } = this.node(tree);
    this.root = entry;
    ul.appendChild(li);
    this.element.appendChild(ul);
  }

  /// The page's element for `n` and the entry that computes its status. An untraced
  /// body has no line of its own: its items stand in its place (`li` is then their list).
  node(n) {
    const children = n.children || [];
    // Items run one after another in every body but a PARALLEL block's; a block's
    // handlers are not among its items.
    const sequential = !(n.kind === "block" && n.parallel === true) && n.kind !== "if";
    if (n.kind === "block" && !n.traced && children.length) {
      const { ul, entries } = this.list(children);
      return { li: ul, entry: { span: null, own: null, kids: entries, sequential, kind: "body" } };
    }
    const li = document.createElement("li");
    const span = document.createElement("span");
    span.className = "node";
    const kind = document.createElement("span");
    kind.className = "kind";
    const label = document.createElement("span");
    span.append(kind, label);
    li.appendChild(span);
    // What the node's own events say, or null when none names it.
    let own = null;
    // Over: the block or handler has ended, and with it everything in it.
    let over = null;
    switch (n.kind) {
      case "block":
        kind.textContent = n.parallel === true ? "PARALLEL" : n.parallel === false ? "SEQUENTIAL" : "BLOCK";
        label.textContent = n.traced ? last(n.name) : "";
        if (n.traced) {
          own = (m) => m.blocks.get(n.name) || "waiting";
          over = (m) => FINISHED.includes(m.blocks.get(n.name));
        }
        break;
      case "handler":
      case "exception_handler":
        kind.textContent = n.kind === "handler" ? "ON" : "ON EXCEPTION";
        label.textContent = n.signal || n.exception || "";
        own = (m) => {
          const h = m.handlers.get(n.name);
          return !h ? "waiting" : h.running ? "running" : "done";
        };
        over = (m) => {
          const h = m.handlers.get(n.name);
          return !!h && !h.running;
        };
        break;
      case "activity": {
        const actors = (n.actors || []).filter((a) => a !== null);
        const who = actors.map((a) => [].concat(a).join(" ")).join(", ");
        kind.textContent = who || "…";
        label.textContent = n.capability;
        if (n.tag) {
          const tag = document.createElement("span");
          tag.className = "tag";
          tag.textContent = `-${n.tag}`;
          span.appendChild(tag);
        }
        const all = actors.length === (n.actors || []).length ? actors : null;
        own = n.line
          ? (m) => {
            const s = statementStatus(m, n.line);
            // A leash pauses by tag; the operator holds by drone.
            return s === "running" && activityStatus(m, n.capability, n.tag, all) === "paused" ? "paused" : s;
          }
          : (m) => activityStatus(m, n.capability, n.tag, all);
        break;
      }
      case "any":
        // The drones are chosen in flight: the line names the group they come from.
        kind.textContent = "ANY";
        label.textContent = `${n.count > 1 ? `${n.count} ` : ""}IN ${n.group}`;
        break;
      default:
        kind.textContent = n.kind.toUpperCase();
        label.textContent = n.signal || n.exception || (n.capability ? `${n.capability}-${n.tag} ${n.action}` : n.block ? `${n.block} ${n.action}` : "");
        // A SIGNAL, a leash or a THROW: done once an event names its line.
        if (n.line && ["signal", "leash", "throw"].includes(n.kind)) own = (m) => statementStatus(m, n.line);
    }
    if (n.line) span.title = `line ${n.line}`;
    let entries = [];
    if (children.length) {
      const made = this.list(children);
      li.appendChild(made.ul);
      entries = made.entries;
    }
    return { li, entry: { span, own, over, kids: entries, sequential, kind: n.kind } };
  }

  list(children) {
    const ul = document.createElement("ul");
    const entries = [];
    for (const c of children) {
      const { li, entry } = this.node(c);
      entries.push(entry);
      if (li.tagName === "UL") {
        const wrap = document.createElement("li");
        wrap.appendChild(li);
        ul.appendChild(wrap);
      } else ul.appendChild(li);
    }
    return { ul, entries };
  }

  update(model) {
    if (this.root) settle(this.root, model, false);
  }
}

/// Computes and shows the status of `entry` and everything in it; returns it. `closed`:
/// an enclosing block or handler is over.
function settle(entry, model, closed) {
  const over = closed || (entry.over ? entry.over(model) : false);
  const kids = entry.kids.map((k) => settle(k, model, over));
  if (entry.sequential) {
    // An item no event names is over once a later item of its body has started.
    const items = entry.kids.map((k, i) => [k, i]).filter(([k]) => !["handler", "exception_handler"].includes(k.kind));
    let later = false;
    for (let j = items.length - 1; j >= 0; j--) {
      const [k, i] = items[j];
      if (kids[i] !== "waiting") {
        later = true;
      } else if (later && !k.own) {
        kids[i] = "done";
        show(k, "done");
      }
    }
  }
  let s = entry.own ? entry.own(model) : derived(entry, kids, over);
  show(entry, s);
  return s;
}

/// The status of a node no event names, from its children's.
function derived(entry, kids, over) {
  const items = kids.filter((_, i) => !["handler", "exception_handler"].includes(entry.kids[i].kind));
  if (items.some((k) => k === "running")) return "running";
  if (items.some((k) => k === "paused")) return "paused";
  const ran = items.filter((k) => FINISHED.includes(k));
  if (!ran.length) return over && entry.kind === "waitfor" ? "done" : "waiting";
  // An IF ran one branch: it is as that branch ended. A body is over when its last item
  // that ran is its last item, or when what holds it is over.
  const finished = entry.kind === "if" || over || FINISHED.includes(items[items.length - 1]);
  if (!finished) return "running";
  if (ran.includes("failed")) return "failed";
  if (ran.every((k) => k === "aborted")) return "aborted";
  return "done";
}

function show(entry, s) {
  if (entry.span && entry.span.dataset.status !== s) entry.span.dataset.status = s;
}

function last(path) {
  const parts = (path || "").split("/");
  return parts[parts.length - 1];
}
