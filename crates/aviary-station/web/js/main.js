// The station's page: loads what the station serves (a folder of missions, or one run),
// and wires the map, the fleet grid, the tree, the log and the controls to the model
// that the live event stream keeps.

import * as api from "./api.js";
import { newModel, observe, drone } from "./model.js";
import { StationMap } from "./map.js";
import { FleetGrid } from "./fleet.js";
import { TreeView } from "./tree.js";
import { Log } from "./log.js";
import { Editor } from "./editor.js";
import { Replay, treeOf } from "./replay.js";

const $ = (id) => document.getElementById(id);

const page = {
  model: newModel(),
  map: new StationMap($("map")),
  tree: new TreeView($("tree")),
  log: new Log($("log"), $("timeline")),
  fleet: null,
  editor: null,
  socket: null,
  about: null,
};
page.fleet = new FleetGrid($("fleet"), (name, action) => droneAction(name, action));
window.aviary = page; // for the browser tests and for a curious operator

function confirmDanger(text) {
  const dialog = $("confirm-dialog");
  $("confirm-text").textContent = text;
  return new Promise((resolve) => {
    dialog.onclose = () => resolve(dialog.returnValue === "ok");
    dialog.showModal();
  });
}

/// A refusal or an error, as an alarm the operator acknowledges.
function refused(what, result) {
  const why = (result.body && result.body.error) || `status ${result.status}`;
  page.model.alarms.push({ id: `refused|${Date.now()}`, kind: "refused", text: `${what}: ${why}`, severe: false, acknowledged: false });
  showAlarms();
}

async function control(path, body, what) {
  const result = await api.call("POST", path, body);
  if (!result.ok) refused(what, result);
  return result;
}

async function droneAction(name, action) {
  if ((action === "land" || action === "home") &&
      !(await confirmDanger(action === "land" ? `Land ${name} where it is? Its activities are aborted.` : `Send ${name} home? Its activities are aborted; the mission goes on with the rest.`)))
    return;
  await control("/api/drone", { drone: name, action }, `${action} ${name}`);
}

function showAlarms() {
  const box = $("alarms");
  box.textContent = "";
  for (const a of page.model.alarms) {
    if (a.acknowledged) continue;
    const div = document.createElement("div");
    div.className = "alarm" + (a.severe ? "" : " warn");
    div.dataset.kind = a.kind;
    const text = document.createElement("span");
    text.textContent = `${a.t !== undefined ? "t = " + a.t.toFixed(1) + " s  " : ""}${a.text}`;
    const ack = document.createElement("button");
    ack.textContent = "Acknowledge";
    ack.onclick = () => { a.acknowledged = true; showAlarms(); };
    div.append(text, ack);
    box.appendChild(div);
  }
  page.shownAlarms = page.model.alarms.length;
}

function render() {
  const m = page.model;
  $("mission-name").textContent = m.mission || (page.about && page.about.run && page.about.run.mission) || "no mission";
  const status = m.paused && m.status === "running" ? "paused" : m.status;
  $("status").textContent = status;
  $("status").dataset.status = status;
  $("clock").textContent = `t = ${m.t.toFixed(1)} s`;
  page.fleet.update(m);
  page.tree.update(m);
  page.log.flush(m);
  page.map.changed();
  if (page.shownAlarms !== m.alarms.length) showAlarms();
  const live = m.status === "running" && !page.replay;
  for (const id of ["pause", "resume", "abort"]) $(id).disabled = !live;
}

let renderQueued = false;
function queueRender() {
  if (renderQueued) return;
  renderQueued = true;
  // The grid, tree and log at most 5 times a second; the map every frame it changed.
  setTimeout(() => { renderQueued = false; render(); }, 200);
  page.map.changed();
}

/// Watches the run the station serves now: its tree, the state so far, then its events.
async function watch() {
  const about = (await api.call("GET", "/api/station")).body;
  page.about = about;
  if (!about || !about.run) return;
  page.showingRun = true;
  page.model = newModel();
  page.map.follow(page.model);
  page.fleet.clear();
  page.log.clear();
  page.map.setWorld(about.map);
  page.tree.show(about.run.tree);
  fillLists(about.run.tree);
  $("trace-file").textContent = about.run.trace ? `trace ${about.run.trace}` : "";
  for (const d of (about.map && about.map.drones) || []) drone(page.model, d.name).pos = d.home;
  const state = await api.call("GET", "/api/state");
  fillSignals((state.ok && state.body.operator_signals) || [], (state.ok && state.body.operator_signal_values) || {});
  if (state.ok) {
    const s = state.body;
    const m = page.model;
    m.mission = s.mission; m.t = s.t || 0; m.status = s.status || "running"; m.paused = !!s.paused;
    for (const b of s.running_blocks || s.blocks || []) m.blocks.set(typeof b === "string" ? b : b.block, "running");
    for (const d of s.drones || []) {
      const x = drone(m, d.name);
      if (d.position) { x.pos = d.position; x.trail.push([d.position[0], d.position[1]]); }
      if (d.battery !== undefined) x.battery = d.battery;
      if (d.state) x.state = d.state;
      // What the state says is as of its time: the events since the start, read next,
      // are older and leave it be.
      if (d.position) x.lastT = m.t;
    }
  }
  vehiclePlan(about.run);
  if (page.socket) page.socket.close();
  page.socket = api.events((e) => {
    if (observe(page.model, e)) page.log.add(e);
    if (e.event === "mission_end" && page.onFlightEnd) page.onFlightEnd(about.run.trace);
    queueRender();
  }, () => queueRender());
  render();
}

/// With MAVLink drones the station plans again with each vehicle's own figures once they
/// answer, as `aviary run` does: its warnings (a reserve under 20 %, a battery the plan
/// says runs out) are alarms, looked for until the plan is made.
async function vehiclePlan(run) {
  let plan = run && run.vehicle_plan;
  // Until the plan is made, or the flight has ended without it (the vehicles never
  // answered).
  while (plan === "due" && !["ok", "failed", "aborted"].includes(page.model.status)) {
    await new Promise((r) => setTimeout(r, 500));
    const about = (await api.call("GET", "/api/station")).body;
    if (!about || !about.run || about.run.mission !== run.mission) return;
    plan = about.run.vehicle_plan;
  }
  if (!Array.isArray(plan)) return;
  for (const w of plan) {
    page.model.alarms.push({
      id: `plan|${w.drone || ""}|${w.text}`, kind: "plan", who: w.drone || null,
      text: `plan with the vehicles' figures: ${w.code}: ${w.text}`, severe: !!w.severe, acknowledged: false,
    });
  }
  showAlarms();
}

function fillLists(tree) {
  const tags = new Set();
  const walk = (n) => {
    if (!n) return;
    if (n.kind === "activity" && n.tag) tags.add(`${n.capability}-${n.tag}`);
    (n.children || []).forEach(walk);
  };
  walk(tree);
  $("tags").innerHTML = "";
  for (const t of tags) $("tags").appendChild(new Option(t));
}

/// The signals the operator may raise: those the mission declares (OPERATOR SIGNAL), as
/// the state lists them; the API refuses any other. `values` are the kinds each carries
/// (`"position"`, ..., null for any), which say how the values field is read.
function fillSignals(names, values) {
  $("signals").innerHTML = "";
  for (const s of names) $("signals").appendChild(new Option(s));
  $("signal-name").placeholder = names.length ? names.join(", ") : "the mission declares no operator signal";
  page.signalValues = values;
  hintValues();
}

/// The values field's hint for the signal named: what it carries, a position's two forms.
function hintValues() {
  const kinds = (page.signalValues || {})[$("signal-name").value.trim()];
  const shown = (k) => (k === "position" ? "GEO(lat, lon) or x, y" : k || "a value");
  $("signal-args").placeholder = !kinds ? "values, comma-separated" : kinds.length ? kinds.map(shown).join("; ") : "no values";
}

/// The values field of the Raise form: a signal that carries one value takes the whole
/// field as that value (`120, 40` is one position); several are split at the commas
/// outside parentheses (`(120, 40), Body`).
function signalValues(name, raw) {
  if (!raw) return [];
  const kinds = (page.signalValues || {})[name];
  if (kinds && kinds.length === 1) return [value(raw)];
  return raw.split(/,(?![^(]*\))/).map(value);
}

/// `radius=200m, rounds=2` as the operator API's values: a number with its unit, a
/// position (`x, y`, `(x, y, z)`, or `GEO(lat, lon[, alt])`, which the server places about
/// the world's origin), TRUE/FALSE, or a name.
function value(text) {
  const t = text.trim();
  const geo = t.match(/^GEO\(\s*(-?[\d.]+)\s*,\s*(-?[\d.]+)\s*(?:,\s*(-?[\d.]+)\s*m?)?\)$/i);
  if (geo) return geo[3] === undefined ? { lat: Number(geo[1]), lon: Number(geo[2]) }
    : { lat: Number(geo[1]), lon: Number(geo[2]), alt: Number(geo[3]) };
  const unit = t.match(/^(-?\d+(?:\.\d+)?)\s*(m|km|s|min|h|m\/s|km\/h|deg|%)?$/);
  if (unit) return unit[2] ? { number: Number(unit[1]), unit: unit[2] } : { number: Number(unit[1]) };
  const pos = t.match(/^\(?\s*(-?[\d.]+)\s*,\s*(-?[\d.]+)\s*(?:,\s*(-?[\d.]+)\s*m?)?\)?$/);
  if (pos) return pos.slice(1).filter((v) => v !== undefined).map(Number);
  if (t === "TRUE" || t === "FALSE") return t === "TRUE";
  return t.replace(/^"(.*)"$/, "$1");
}

function splitTag(text) {
  const i = text.lastIndexOf("-");
  return i > 0 ? [text.slice(0, i), text.slice(i + 1)] : [text, ""];
}

function wireControls() {
  $("pause").onclick = () => control("/api/pause", {}, "pause");
  $("resume").onclick = () => control("/api/resume", {}, "resume");
  $("abort").onclick = async () => {
    if (await confirmDanger("Abort the mission? Every drone returns home.")) control("/api/abort", {}, "abort");
  };
  $("token").onclick = () => api.askToken();
  $("leash-form").onsubmit = (ev) => {
    ev.preventDefault();
    const activity = $("leash-tag").value.trim();
    const action = $("leash-action").value.trim();
    const args = {};
    for (const part of $("leash-args").value.split(",")) {
      const [k, v] = part.split("=");
      if (k && v !== undefined) args[k.trim()] = value(v);
    }
    const body = { activity, action };
    if (Object.keys(args).length) body.args = args;
    control("/api/leash", body, `leash ${activity} ${action}`);
  };
  $("signal-form").onsubmit = (ev) => {
    ev.preventDefault();
    const name = $("signal-name").value.trim();
    const args = signalValues(name, $("signal-args").value.trim());
    control("/api/signal", { name, args }, `signal ${name}`);
  };
  $("signal-name").oninput = hintValues;
  window.addEventListener("keydown", (e) => {
    if (e.key === " " && e.target === document.body && page.about && page.about.mode !== "replay") {
      e.preventDefault();
      control(page.model.paused ? "/api/resume" : "/api/pause", {}, "pause");
    }
  });
}

// The folder's missions: open, edit, check, save, fly.
async function station() {
  $("files").hidden = false;
  const editor = (page.editor = new Editor(page.about));
  const listing = (await api.call("GET", "/api/station/files")).body || { missions: [], worlds: [] };
  const missions = $("mission-file"), worlds = $("world-file");
  for (const m of listing.missions) missions.appendChild(new Option(m));
  // "No world", as `aviary check` has for a mission with none beside it.
  worlds.appendChild(new Option("(no world)", ""));
  for (const w of listing.worlds) worlds.appendChild(new Option(w));
  const open = async (which, path) => {
    if (!path) { editor.load(which, "", ""); return; }
    const file = await api.call("GET", `/api/station/file?path=${encodeURIComponent(path)}`);
    if (file.ok) editor.load(which, path, file.body.text);
    else refused(`open ${path}`, file);
  };
  // The operator opens another mission or world (an event; the page's own first opening
  // has none): a flight that has ended leaves the map and the tree to it.
  missions.onchange = async (event) => {
    if (event) leaveFinishedRun();
    const stem = missions.value.replace(/\.mission$/, "");
    // The world beside the mission, as `aviary check` takes it; none when there is none.
    const beside = listing.worlds.find((w) => w === `${stem}.world.toml`);
    worlds.value = beside || "";
    await open("mission", missions.value);
    await open("world", worlds.value);
    check();
  };
  worlds.onchange = () => {
    leaveFinishedRun();
    return open("world", worlds.value).then(check);
  };
  $("edit-mission").onclick = () => { editor.show("mission"); tabs("mission"); };
  $("edit-world").onclick = () => { editor.show("world"); tabs("world"); };
  const tabs = (which) => {
    $("edit-mission").classList.toggle("active", which === "mission");
    $("edit-world").classList.toggle("active", which === "world");
  };
  const pair = () => ({ mission: { path: editor.files.mission.path, text: editor.files.mission.text },
                        world: { path: editor.files.world.path, text: editor.files.world.text } });
  const check = async () => {
    const result = await api.call("POST", "/api/station/check", pair());
    if (!result.ok) return refused("check", result);
    showCheck(result.body);
  };
  $("check").onclick = check;
  $("save").onclick = async () => {
    for (const which of ["mission", "world"]) {
      const f = editor.files[which];
      if (!f.dirty) continue;
      const r = await control("/api/station/save", { path: f.path, text: f.text }, `save ${f.path}`);
      if (r.ok) f.dirty = false;
    }
  };
  $("fly").onclick = async () => {
    const speed = $("speed").value.trim();
    const body = { ...pair(), speed: speed ? Number(speed) : null };
    const result = await api.call("POST", "/api/station/fly", body);
    if (!result.ok) {
      if (result.body && result.body.check) showCheck(result.body.check);
      return refused("fly", result);
    }
    await watch();
  };
  $("campaign").onclick = async () => {
    const runs = Number($("campaign-runs").value);
    const summary = $("campaign-summary");
    summary.textContent = `flying ${runs} runs...`;
    summary.className = "summary";
    $("campaign").disabled = true;
    const result = await api.call("POST", "/api/station/campaign", { ...pair(), runs, seed: 0 });
    $("campaign").disabled = false;
    if (!result.ok) {
      summary.textContent = "";
      if (result.body && result.body.check) showCheck(result.body.check);
      return refused("campaign", result);
    }
    // The report's first lines: the campaign, its seeds and how often it succeeded.
    const lines = result.body.text.split("\n");
    summary.textContent = lines.find((l) => l.startsWith("success:")) || lines[0];
    summary.className = "summary " + (/success: (\d+) of \1 /.test(summary.textContent) ? "good" : "bad");
    const link = document.createElement("a");
    link.href = URL.createObjectURL(new Blob([result.body.html], { type: "text/html" }));
    link.download = editor.files.mission.path.replace(/^.*\//, "").replace(/\.mission$/, "") + "-campaign.html";
    document.body.appendChild(link);
    link.click();
    link.remove();
  };
  records(listing.traces || []);
  if (listing.missions.length) {
    const preferred = listing.missions.find((m) => /search_and_rescue|paper/.test(m)) || listing.missions[0];
    missions.value = preferred;
    await missions.onchange();
  }
}

/// The folder's recorded flights (`traces/`): replayed in this page, or their report
/// saved, each on the world it was flown in (the trace names it).
function records(traces) {
  const list = $("trace-list");
  const fill = (paths, chosen) => {
    list.textContent = "";
    for (const t of paths) list.appendChild(new Option(t));
    list.value = chosen || paths[paths.length - 1] || "";
    $("replay-trace").disabled = $("report-trace").disabled = !list.value;
  };
  fill(traces);
  // A flight that ended adds its trace: the list is read again, the new one chosen.
  page.onFlightEnd = async (trace) => {
    const listing = (await api.call("GET", "/api/station/files")).body;
    if (listing) fill(listing.traces || [], trace);
  };
  $("replay-trace").onclick = () => {
    const q = new URLSearchParams({ replay: list.value });
    location.href = `/?${q}`;
  };
  $("report-trace").onclick = async () => {
    // On the world the trace names, as the station has it; without one if it changed.
    const q = new URLSearchParams({ path: list.value });
    const response = await api.raw(`/api/station/report?${q}`);
    if (!response.ok) return refused(`report of ${list.value}`, { status: response.status, body: await response.json().catch(() => null) });
    const link = document.createElement("a");
    link.href = URL.createObjectURL(await response.blob());
    link.download = list.value.replace(/^.*\//, "").replace(/\.jsonl$/, "") + ".html";
    document.body.appendChild(link);
    link.click();
    link.remove();
  };
}

/// A flight that has ended gives the map and the tree back to what the editor opens: its
/// drones leave the map. One under way keeps them.
function leaveFinishedRun() {
  if (!page.showingRun || ["running", "paused"].includes(page.model.status)) return;
  page.showingRun = false;
  page.model = newModel();
  page.map.follow(page.model);
  page.fleet.clear();
}

function showCheck(report) {
  page.checked = report;
  page.editor.mark(report.diagnostics);
  const summary = $("check-summary");
  // The server's count, as `aviary check` prints it: notes are not warnings.
  const counted = report.summary ? `, ${report.summary}` : "";
  summary.textContent = report.errors
    ? `${report.summary}: the mission cannot fly`
    : report.flyable
      ? `no errors${counted}: ready to fly`
      : !page.editor.files.world.path
        ? `no errors${counted}: choose a world to fly`
        : `no errors${counted}: no MISSION to fly`;
  summary.className = "summary " + (report.errors ? "bad" : "good");
  $("fly").disabled = !report.flyable;
  showPlan(report.plan);
  // The map and the tree show what the editor has open, unless they show a flight (one
  // under way, or one that has ended until the operator opens something else).
  if (report.map && !page.showingRun) page.map.setWorld(report.map);
  if (report.tree && !page.showingRun) page.tree.show(report.tree);
}

function showPlan(plan) {
  const box = $("plan");
  box.textContent = "";
  if (!plan || !plan.drones) { box.textContent = "no plan: fix the errors first"; return; }
  const end = Math.max(plan.mission_time || 1, 1);
  const head = document.createElement("div");
  head.textContent = `mission about ${Math.round(end)} s`;
  box.appendChild(head);
  for (const d of plan.drones) {
    const lane = document.createElement("div");
    lane.className = "lane";
    const who = document.createElement("span");
    who.className = "who"; who.textContent = d.drone;
    const bar = document.createElement("div");
    bar.className = "bar";
    for (const a of d.activities || []) {
      const act = document.createElement("div");
      act.className = "act";
      act.style.left = `${(100 * a.start) / end}%`;
      act.style.width = `${(100 * Math.max(a.end - a.start, 0)) / end}%`;
      act.title = `${a.what} ${a.start.toFixed(0)}–${a.end.toFixed(0)} s (${a.at || ""})`;
      bar.appendChild(act);
    }
    const left = document.createElement("span");
    left.className = "left";
    left.textContent = `${Math.round((d.battery_left || 0) * 100)} %`;
    left.title = "battery left at the end";
    lane.append(who, bar, left);
    box.appendChild(lane);
  }
}

// A recorded trace, played back: the controls steer nothing, the scrubber picks the time.
// `aviary replay` serves one trace; in `aviary gcs` the page replays one of the folder's
// (`recorded`: its path), on the world it was flown in, whatever world is chosen above.
async function replay(recorded) {
  for (const id of ["pause", "resume", "abort"]) $(id).hidden = true;
  for (const id of ["leash-form", "signal-form"]) $(id).hidden = true;
  document.querySelector("#side h2:nth-of-type(2)").hidden = true;
  page.fleet.act = null;
  $("replay").hidden = false;
  const query = recorded ? `?path=${encodeURIComponent(recorded.path)}` : "";
  const response = await api.raw(`/api/station/trace${query}`);
  if (!response.ok) return refused("replay", { status: response.status, body: await response.json().catch(() => null) });
  const name = response.headers.get("x-aviary-trace") || "trace";
  const events = (await response.text()).split("\n").filter((l) => l.trim()).map((l) => JSON.parse(l));
  let world = page.about.map;
  if (recorded) {
    $("leave-replay").hidden = false;
    const shown = await api.call("GET", `/api/station/world?trace=${encodeURIComponent(recorded.path)}`);
    // The folder's copy of that world changed since the flight: said, and drawn without.
    if (!shown.ok) refused("the world of this trace", shown);
    world = shown.ok ? shown.body : null;
  }
  page.map.setWorld(world);
  page.tree.show(treeOf(events));
  const homes = new Map(((world && world.drones) || []).map((d) => [d.name, d.home]));
  const r = new Replay(events, homes, (model, logged) => {
    page.model = model;
    for (const e of logged) page.log.add(e);
    queueRender();
  }, (model) => {
    page.model = model;
    page.map.follow(model);
    page.fleet.clear();
    page.log.clear();
  });
  page.replay = r;
  const scrub = $("scrub");
  scrub.max = String(r.end);
  const shown = () => {
    scrub.value = String(r.t);
    $("replay-time").textContent = `${r.t.toFixed(1)} / ${r.end.toFixed(1)} s`;
    $("play").textContent = r.playing ? "Pause" : "Play";
  };
  r.onchange = shown;
  scrub.oninput = () => { r.seek(Number(scrub.value)); shown(); };
  $("replay-speed").onchange = () => { r.speed = Number($("replay-speed").value); };
  $("play").onclick = () => { if (r.playing) r.pause(); else r.play(); shown(); };
  window.addEventListener("keydown", (e) => {
    if (e.key === " " && e.target === document.body) { e.preventDefault(); $("play").click(); }
  });
  $("mission-name").textContent = name;
  r.seek(0);
  shown();
}

async function start() {
  wireControls();
  const about = (await api.call("GET", "/api/station")).body;
  page.about = about;
  if (!about) return;
  if (about.mode !== "station") $("files") && document.querySelector("main").classList.add("no-files");
  const asked = new URLSearchParams(location.search);
  if (about.mode === "station" && asked.get("replay")) {
    document.querySelector("main").classList.add("no-files");
    return replay({ path: asked.get("replay") });
  }
  if (about.mode === "station") await station();
  if (about.mode === "replay") return replay();
  if (about.run) await watch();
  render();
}

start();
