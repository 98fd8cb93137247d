// Replay: a recorded trace played back. The state at a time is the trace's events up to
// that time folded into the model, as a live run folds them; going back starts again from
// the first event. Positions are the last telemetry at or before the time.

import { newModel, observe, drone } from "./model.js";

export class Replay {
  /// `events` in trace order; `show(model, events)` draws the state; `reset()` clears
  /// what shows it.
  constructor(events, homes, show, reset) {
    this.events = events;
    this.homes = homes;
    this.end = events.length ? events[events.length - 1].t : 0;
    this.show = show;
    this.reset = reset;
    this.playing = false;
    this.speed = 10;
    this.fresh();
  }

  fresh() {
    this.model = newModel();
    for (const [name, home] of this.homes) drone(this.model, name).pos = home;
    this.index = 0;
    this.t = 0;
    this.reset(this.model);
  }

  /// The state at mission time `t`.
  seek(t) {
    t = Math.max(0, Math.min(this.end, t));
    if (t < this.t) this.fresh();
    const logged = [];
    while (this.index < this.events.length && this.events[this.index].t <= t) {
      const e = this.events[this.index++];
      if (observe(this.model, e)) logged.push(e);
    }
    this.t = t;
    this.model.t = t;
    this.show(this.model, logged);
  }

  play() {
    if (this.t >= this.end) this.seek(0);
    this.playing = true;
    let last = performance.now();
    const step = (now) => {
      if (!this.playing) return;
      const dt = (now - last) / 1000;
      last = now;
      this.seek(this.t + dt * this.speed);
      if (this.t >= this.end) this.playing = false;
      else requestAnimationFrame(step);
      this.onchange && this.onchange();
    };
    requestAnimationFrame(step);
  }

  pause() {
    this.playing = false;
  }
}

/// What the tree can show of a trace without the mission: its blocks and handlers, in the
/// order they first started.
export function treeOf(events) {
  const children = [];
  const seen = new Set();
  let root = null;
  for (const e of events) {
    if (e.event === "block_start" && !seen.has(e.block)) {
      seen.add(e.block);
      const node = { kind: "block", name: e.block, traced: true, parallel: null, children: [] };
      if (!root) root = node; else children.push(node);
    }
    if (e.event === "handler_start" && !seen.has(e.handler)) {
      seen.add(e.handler);
      children.push({ kind: "handler", name: e.handler, signal: e.signal, children: [] });
    }
  }
  if (!root) return null;
  root.children = children;
  return root;
}
