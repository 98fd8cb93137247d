// The event log (every event but telemetry and middle-layer calls, newest last, the last
// 2000 kept) and the timeline: signals, exceptions, finds and operator actions as marks
// over the mission's time.

import { describe } from "./model.js";

const KEEP = 2000;
const COLORS = { signal: "#1c64d1", exception: "#c2352b", operator: "#7b4bc4", find: "#1f8a4c", end: "#16202e" };

export class Log {
  constructor(list, canvas) {
    this.list = list;
    this.canvas = canvas;
    this.pending = [];
  }

  clear() {
    this.list.textContent = "";
    this.pending = [];
  }

  add(e) {
    this.pending.push(e);
  }

  flush(model) {
    if (this.pending.length) {
      const stick = this.list.scrollTop + this.list.clientHeight >= this.list.scrollHeight - 4;
      const fragment = document.createDocumentFragment();
      for (const e of this.pending.slice(-KEEP)) {
        const li = document.createElement("li");
        li.className = e.event;
        const t = document.createElement("span");
        t.className = "t";
        t.textContent = (e.t || 0).toFixed(1);
        li.append(t, describe(e));
        fragment.appendChild(li);
      }
      this.pending = [];
      this.list.appendChild(fragment);
      while (this.list.childElementCount > KEEP) this.list.firstElementChild.remove();
      if (stick) this.list.scrollTop = this.list.scrollHeight;
    }
    this.timeline(model);
  }

  timeline(model, cursor) {
    const c = this.canvas;
    const width = c.clientWidth || 300;
    if (c.width !== width) c.width = width;
    const ctx = c.getContext("2d");
    ctx.clearRect(0, 0, c.width, c.height);
    const end = Math.max(model.t, 1);
    const rows = ["signal", "exception", "operator", "find"];
    ctx.font = "9px system-ui, sans-serif";
    rows.forEach((kind, i) => {
      ctx.fillStyle = "#9aa3b5";
      ctx.fillText(kind, 2, 10 + i * 11);
    });
    for (const m of model.marks) {
      const row = Math.max(0, rows.indexOf(m.kind));
      const x = 50 + ((c.width - 56) * m.t) / end;
      ctx.fillStyle = COLORS[m.kind] || "#444";
      ctx.fillRect(x - 1, 2 + row * 11, 3, 9);
    }
    if (cursor !== undefined) {
      const x = 50 + ((c.width - 56) * cursor) / end;
      ctx.fillStyle = "#16202e";
      ctx.fillRect(x, 0, 2, c.height);
    }
  }
}
