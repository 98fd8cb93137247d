// What the page knows of the mission, folded from trace events: the same events a
// trace file holds, so a live run and a replay build the same state.

// Written by the station from the language's own list (not a file of web/).
import { DRONE_FAULTS } from "./builtins.js";

export function newModel() {
  return {
    t: 0,
    mission: null,
    status: "idle",
    reason: null,
    paused: false,
    drones: new Map(),     // name -> drone
    blocks: new Map(),     // block name -> status
    handlers: new Map(),   // handler name -> {running, done}
    activities: new Map(), // "capability|tag|actor" -> {running, done, aborted, failed, paused}
    statements: new Map(), // line of a statement of the MISSION's file -> {running, done, aborted, failed, paused}
    finds: [],
    spots: [],             // on the map: {t, at, kind: "signal" | "drop", text}
    marks: [],             // timeline: {t, kind, text}
    log: [],
    alarms: [],
    version: 0,
  };
}

export function drone(model, name) {
  let d = model.drones.get(name);
  if (!d) {
    d = { name, pos: null, battery: null, state: "unknown", speed: 0, heading: 0, trail: [],
          activity: "", working: [], streaming: false, link: "ok", held: false, withdrawn: false, lastT: null, alarms: new Set() };
    model.drones.set(name, d);
  }
  return d;
}

const TRAIL = 240;

/// Halves the older part of a trail in place, keeping its first and the recent points.
function thin(trail) {
  const older = trail.length - TRAIL / 2;
  let kept = 0;
  for (let i = 0; i < older; i += 2) trail[kept++] = trail[i];
  trail.copyWithin(kept, older);
  trail.length = kept + (trail.length - older);
}

function key(capability, tag, actor) {
  return `${capability}|${tag || ""}|${actor}`;
}

function bump(map, k, field, by) {
  let v = map.get(k);
  if (!v) { v = { running: 0, done: 0, aborted: 0, failed: 0, paused: 0 }; map.set(k, v); }
  v[field] = Math.max(0, v[field] + by);
  return v;
}

/// Whether a trace value is a position: two or three numbers.
function isPosition(v) {
  return Array.isArray(v) && (v.length === 2 || v.length === 3) && v.every((x) => typeof x === "number");
}

/// An alarm raised by event `e`, at the event's own time: a page opened after the run
/// reads the whole run's events after the state at its end, so the clock is no guide.
function alarm(model, e, kind, who, text, severe = true) {
  const id = `${kind}|${who || ""}`;
  if (model.alarms.some((a) => a.id === id && !a.acknowledged)) return;
  const t = typeof e.t === "number" ? e.t : model.t;
  model.alarms.push({ id, kind, who, text, t, severe, acknowledged: false });
}

/// Whether `e` is no older than what the model already knows of drone `d`: a page opened
/// late gets the state now, then the events since the start, which must not move a drone
/// back to where it was.
function current(d, e) {
  return d.lastT === null || !(e.t < d.lastT);
}

/// Folds one event into the model; returns whether it is worth a line in the log.
export function observe(model, e) {
  model.version++;
  if (typeof e.t === "number") model.t = Math.max(model.t, e.t);
  switch (e.event) {
    case "mission_start":
      model.mission = e.mission; model.status = "running"; break;
    case "mission_end":
      model.status = e.status; model.reason = e.reason || null;
      model.marks.push({ t: e.t, kind: "end", text: `mission ${e.status}` });
      if (e.status === "failed") alarm(model, e, "failed", null, `mission failed: ${e.reason || ""}`);
      break;
    case "block_start": model.blocks.set(e.block, "running"); break;
    case "block_end": model.blocks.set(e.block, e.status === "ok" ? "done" : e.status); break;
    case "handler_start": bump(model.handlers, e.handler, "running", 1); break;
    case "handler_end": {
      const v = bump(model.handlers, e.handler, "running", -1); v.done++; break;
    }
    case "capability_start": {
      // The statement itself, by its line: what the tree follows (two statements of one
      // drone and capability are two lines).
      if (e.line) bump(model.statements, e.line, "running", 1);
      for (const a of e.actor.split(" ")) {
        bump(model.activities, key(e.capability, e.tag, a), "running", 1);
        // What the drone works on, outermost first: a capability and the ones it calls
        // (`Deliver › FlyTo › TakeOff`), each gone when it ends.
        const d = drone(model, a);
        d.working.push(e.tag ? `${e.capability}-${e.tag}` : e.capability);
        d.activity = d.working.join(" › ");
      }
      break;
    }
    case "capability_end": {
      if (e.line) {
        const v = bump(model.statements, e.line, "running", -1);
        v[e.status === "ok" ? "done" : e.status === "failed" ? "failed" : "aborted"]++;
      }
      for (const a of e.actor.split(" ")) {
        const v = bump(model.activities, key(e.capability, e.tag, a), "running", -1);
        v[e.status === "ok" ? "done" : e.status === "failed" ? "failed" : "aborted"]++;
        const d = drone(model, a);
        const i = d.working.lastIndexOf(e.tag ? `${e.capability}-${e.tag}` : e.capability);
        if (i >= 0) d.working.splice(i, 1);
        d.activity = d.working.join(" › ");
      }
      break;
    }
    case "leash": {
      if (e.line) bump(model.statements, e.line, "done", 1);
      model.marks.push({ t: e.t, kind: "operator", text: `${e.capability}-${e.tag} ${e.action}` });
      for (const [k, v] of model.activities) {
        if (k.startsWith(`${e.capability}|${e.tag}|`)) {
          if (e.action === "PAUSE") v.paused = v.running;
          if (e.action === "RESUME") v.paused = 0;
        }
      }
      return true;
    }
    case "signal": {
      if (e.line) bump(model.statements, e.line, "done", 1);
      model.marks.push({ t: e.t, kind: "signal", text: e.name });
      // A signal that carries a position (a find, the operator's `Found`) is marked where
      // it says.
      const at = (e.args || []).find(isPosition);
      if (at) model.spots.push({ t: e.t, at, kind: "signal", text: `${e.name}${e.actor ? ` from ${e.actor}` : e.by ? ` from the ${e.by}` : ""}` });
      if (e.name === "BatteryLow" && e.actor) alarm(model, e, "battery", e.actor, `${e.actor}: battery low`, false);
      if (e.name === "ConnectionRestored" && e.actor) drone(model, e.actor).link = "ok";
      break;
    }
    case "exception": {
      if (e.line) bump(model.statements, e.line, "done", 1);
      model.marks.push({ t: e.t, kind: "exception", text: e.name });
      if (e.actor) {
        if (e.name === "ConnectionLost") drone(model, e.actor).link = "lost";
      }
      const what = `${e.name}${e.actor ? " on " + e.actor : ""}`;
      if (!e.handled) alarm(model, e, "unhandled", e.actor, `unhandled exception ${what}`);
      else if (DRONE_FAULTS.has(e.name))
        alarm(model, e, e.name, e.actor, `${what}: ${(e.args || []).join(" ")}`);
      // The simulator's separation layer: a motion that waited for another drone to make
      // room until it timed out (the trace's `cause`, not its words).
      else if (e.cause === "separation")
        alarm(model, e, "separation", e.actor, `${what}: ${(e.args || []).join(" ")}`, false);
      break;
    }
    case "operator":
      model.marks.push({ t: e.t, kind: "operator", text: `${e.action}${e.drone ? " " + e.drone : ""}` });
      if (e.drone) {
        const d = drone(model, e.drone);
        if (e.action === "hold") d.held = true;
        if (e.action === "resume") d.held = false;
        if (e.action === "return_home" || e.action === "land") { d.held = false; d.withdrawn = true; }
      } else if (e.action === "pause") model.paused = true;
      else if (e.action === "resume") model.paused = false;
      return true;
    case "autopilot":
      // A drone acting on its own (a failsafe): the operator must see it at once.
      model.marks.push({ t: e.t, kind: "exception", text: `${e.actor}: ${e.action}` });
      alarm(model, e, "autopilot", e.actor, `${e.actor}, on its own: ${e.action.replace("_", " ")} (${e.reason})`, e.action !== "hold");
      break;
    case "detection":
      model.finds.push({ t: e.t, actor: e.actor, kind: e.kind, at: e.location });
      model.marks.push({ t: e.t, kind: "find", text: `${e.kind} by ${e.actor}` });
      break;
    case "telemetry": {
      const d = drone(model, e.actor);
      if (!current(d, e)) return false;
      const [x, y, z] = e.position;
      if (d.pos && d.lastT !== null && e.t > d.lastT) {
        const dx = x - d.pos[0], dy = y - d.pos[1], dz = z - d.pos[2];
        const dt = e.t - d.lastT;
        d.speed = Math.hypot(dx, dy, dz) / dt;
        if (Math.hypot(dx, dy) > 0.05) d.heading = Math.atan2(dx, dy);
      }
      d.pos = [x, y, z]; d.battery = e.battery; d.state = e.state; d.lastT = e.t;
      d.trail.push([x, y]);
      // Thinned now and then, not at every sample: the older points are halved, so the
      // trail keeps the whole flight, finer where it is recent, in at most 1.5 × TRAIL
      // points (a thousand drones' telemetry stays cheap).
      if (d.trail.length > TRAIL * 1.5) thin(d.trail);
      if (e.battery < 0.2) alarm(model, e, "battery", e.actor, `${e.actor}: battery ${(e.battery * 100).toFixed(0)} %`, e.battery < 0.1);
      return false;
    }
    case "api_done": {
      // Where the call left the drone: the last word on a landing, which may come
      // between two telemetry samples (the fleet's return at the end, an abort).
      const d = drone(model, e.actor);
      if (e.status === "ok" && e.function === "ReleasePayload" && e.position)
        model.spots.push({ t: e.t, at: e.position, kind: "drop", text: `payload dropped by ${e.actor}` });
      if (e.status === "ok" && (e.function === "StartStreaming" || e.function === "StopStreaming"))
        d.streaming = e.function === "StartStreaming";
      if (!current(d, e)) return false;
      if (e.position) d.pos = e.position;
      if (e.status === "ok" && (e.function === "Land" || e.function === "ReturnToLaunch")) {
        d.state = "Landed"; d.speed = 0;
      }
      return false;
    }
    case "api_call":
      return false;
  }
  return true;
}

/// The status of the statement on `line` (of the MISSION's file), from the events that
/// name it; `held`: whether a drone it runs on is held by the operator or paused.
export function statementStatus(model, line, held = false) {
  const v = model.statements.get(line);
  if (!v) return "waiting";
  if ((v.paused || held || model.paused) && v.running) return "paused";
  if (v.running) return "running";
  if (v.failed) return "failed";
  if (v.aborted && !v.done) return "aborted";
  return "done";
}

/// The status of an activity node: its drones' instances, summed.
export function activityStatus(model, capability, tag, actors) {
  let sum = { running: 0, done: 0, aborted: 0, failed: 0, paused: 0 };
  const add = (v) => { if (v) for (const k in sum) sum[k] += v[k]; };
  let held = false;
  if (actors && actors.length) {
    for (const a of actors) for (const name of [].concat(a || [])) {
      add(model.activities.get(key(capability, tag, name)));
      held = held || !!model.drones.get(name)?.held;
    }
  } else {
    const prefix = `${capability}|${tag || ""}|`;
    for (const [k, v] of model.activities) if (k.startsWith(prefix)) add(v);
  }
  if ((sum.paused || held || model.paused) && sum.running) return "paused";
  if (sum.running) return "running";
  if (sum.failed) return "failed";
  if (sum.aborted && !sum.done) return "aborted";
  if (sum.done) return "done";
  return "waiting";
}

/// A line of the log for an event.
export function describe(e) {
  switch (e.event) {
    case "mission_start": return `mission ${e.mission} starts`;
    case "mission_end": return `mission ${e.status}${e.reason ? ": " + e.reason : ""}`;
    case "block_start": return `block ${e.block} starts`;
    case "block_end": return `block ${e.block} ${e.status}`;
    case "capability_start": return `${e.actor} ${e.capability}${e.tag ? "-" + e.tag : ""} starts`;
    case "capability_end": return `${e.actor} ${e.capability}${e.tag ? "-" + e.tag : ""} ${e.status}`;
    case "handler_start": return `handler ${e.handler} starts${e.actor ? " (" + e.actor + ")" : ""}`;
    case "handler_end": return `handler ${e.handler} ends`;
    case "signal": return `signal ${e.name}${e.actor ? " from " + e.actor : ""}${e.args && e.args.length ? " " + JSON.stringify(e.args) : ""}`;
    case "exception": return `exception ${e.name}${e.actor ? " on " + e.actor : ""}${e.handled ? " handled" : " UNHANDLED"} ${(e.args || []).join(" ")}${e.skipped ? ` (passed over: ${e.skipped})` : ""}`;
    case "leash": return `leash ${e.capability}-${e.tag} ${e.action}`;
    case "operator": return `operator: ${e.action}${e.drone ? " " + e.drone : ""}`;
    case "autopilot": return `autopilot of ${e.actor}, on its own: ${e.action.replace("_", " ")} (${e.reason})`;
    case "detection": return `${e.actor} found ${e.kind} at (${e.location.map((v) => v.toFixed(0)).join(", ")})`;
    default: return `${e.event}`;
  }
}
