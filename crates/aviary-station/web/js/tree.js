// The mission's block tree, with the live status of every block, activity and handler:
// waiting, running, paused, done, aborted or failed, from the trace's events.

import { activityStatus } from "./model.js";

export class TreeView {
  constructor(element) {
    this.element = element;
    this.nodes = []; // [{span, status: () => string}]
  }

  show(tree) {
    this.element.textContent = "";
    this.nodes = [];
    if (!tree) {
      this.element.textContent = "no mission yet";
      return;
    }
    const ul = document.createElement("ul");
    ul.appendChild(this.node(tree));
    this.element.appendChild(ul);
  }

  node(n) {
    const li = document.createElement("li");
    const span = document.createElement("span");
    span.className = "node";
    const kind = document.createElement("span");
    kind.className = "kind";
    const label = document.createElement("span");
    span.append(kind, label);
    li.appendChild(span);
    let status = () => "waiting";
    switch (n.kind) {
      case "block":
        kind.textContent = n.parallel === true ? "PARALLEL" : n.parallel === false ? "SEQUENTIAL" : "BLOCK";
        label.textContent = n.traced ? last(n.name) : "";
        if (n.traced) status = (m) => m.blocks.get(n.name) || "waiting";
        if (!n.traced && n.children && n.children.length) {
          // An untraced body adds no line of its own: its items stand for it.
          return this.list(n.children);
        }
        break;
      case "handler":
      case "exception_handler":
        kind.textContent = n.kind === "handler" ? "ON" : "ON EXCEPTION";
        label.textContent = n.signal || n.exception || "";
        status = (m) => {
          const h = m.handlers.get(n.name);
          return !h ? "waiting" : h.running ? "running" : "done";
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
        status = (m) => activityStatus(m, n.capability, n.tag, actors.length === (n.actors || []).length ? actors : null);
        break;
      }
      case "any":
        // The drones are chosen in flight: the line names the group they come from.
        kind.textContent = "ANY";
        label.textContent = `${n.count > 1 ? `${n.count} ` : ""}IN ${n.group}`;
        break;
      default:
        kind.textContent = n.kind.toUpperCase();
        label.textContent = n.signal || n.exception || (n.capability ? `${n.capability}-${n.tag} ${n.action}` : "");
    }
    if (n.line) span.title = `line ${n.line}`;
    this.nodes.push({ span, status });
    if (n.children && n.children.length) li.appendChild(this.list(n.children));
    return li;
  }

  list(children) {
    const ul = document.createElement("ul");
    for (const c of children) {
      const item = this.node(c);
      if (item.tagName === "UL") {
        const li = document.createElement("li");
        li.appendChild(item);
        ul.appendChild(li);
      } else ul.appendChild(item);
    }
    return ul;
  }

  update(model) {
    for (const { span, status } of this.nodes) {
      const s = status(model);
      if (span.dataset.status !== s) span.dataset.status = s;
    }
  }
}

function last(path) {
  const parts = (path || "").split("/");
  return parts[parts.length - 1];
}
