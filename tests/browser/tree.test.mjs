// The mission tree tells the truth: each node's state, at the end of a flight, is what the
// trace says of that very statement, for every kind of node (blocks, activities, WAITFOR,
// IF and its branches, FOR, SIGNAL, a handler), and a statement that never ran stays
// waiting even when the same drone ran the same capability elsewhere.

import { test, before, after } from "node:test";
import assert from "node:assert/strict";
import { readFileSync } from "node:fs";
import { join } from "node:path";
import { browser, choose, examples, open, shot, start } from "./harness.mjs";

let station, chromium, dir;

before(async () => {
  dir = examples();
  station = await start(["gcs", dir, "--listen", "0"]);
  chromium = await browser();
});

after(async () => {
  await chromium?.close();
  station?.process.kill("SIGTERM");
});

/// Each node of the tree as shown: its line (when it has one), kind, label and state.
function nodes(page) {
  return page.evaluate(() => [...document.querySelectorAll("#tree .node")].map((n) => ({
    line: Number((n.title || "").replace(/^line /, "")) || null,
    kind: n.querySelector(".kind").textContent,
    label: n.querySelector(".kind").nextSibling.textContent,
    status: n.dataset.status,
  })));
}

test("every node of the tree ends in the state the trace gives its own statement", async () => {
  const page = await open(chromium, station);
  await choose(page, "drills/tree.mission");
  await page.fill("#speed", "50");
  await page.click("#fly");
  await page.waitForFunction(() => window.aviary.model.mission === "Tree_Truth" && window.aviary.model.status === "ok", null, { timeout: 120000 });
  await page.waitForTimeout(300);
  const shown = await nodes(page);
  const at = (line) => shown.find((n) => n.line === line);
  const source = readFileSync(join(dir, "drills/tree.mission"), "utf8").split("\n");
  const lineOf = (text, from = 0) => source.findIndex((l, i) => i >= from && l.trim() === text) + 1;

  // The trace of the flight, for what each statement did.
  const traceFile = (await page.textContent("#trace-file")).replace(/^trace /, "");
  const events = readFileSync(join(dir, traceFile), "utf8").trim().split("\n").map((l) => JSON.parse(l));
  const endedOk = (line) => events.some((e) => e.event === "capability_end" && e.line === line && e.status === "ok");

  // Activities: done exactly when the trace ended that line's statement.
  for (const n of shown.filter((x) => x.line && !["SEQUENTIAL", "PARALLEL", "ON", "IF", "WAITFOR", "FOR", "SIGNAL", "BRANCH", "OTHERWISE"].includes(x.kind))) {
    assert.equal(n.status, endedOk(n.line) ? "done" : "waiting", `line ${n.line} (${n.kind} ${n.label})`);
  }
  // Two `scout ReturnHome`: the one in ELSE never ran, the last one did.
  const otherwise = lineOf("scout ReturnHome");
  const last = lineOf("scout ReturnHome", otherwise);
  assert.ok(otherwise > 0 && last > otherwise);
  assert.equal(at(otherwise).status, "waiting", "the ELSE branch's ReturnHome never ran");
  assert.equal(at(last).status, "done");
  assert.ok(!endedOk(otherwise) && endedOk(last), "as the trace says");
  // Every other kind of node: none is left grey.
  for (const kind of ["WAITFOR", "IF", "FOR", "SIGNAL", "ON", "SEQUENTIAL", "PARALLEL"]) {
    const of = shown.filter((n) => n.kind === kind);
    assert.ok(of.length > 0, `a ${kind} node`);
    for (const n of of) assert.equal(n.status, "done", `${kind} ${n.label} (line ${n.line})`);
  }
  // The SIGNAL's own event names its line.
  assert.ok(events.some((e) => e.event === "signal" && e.name === "Go" && e.line === lineOf("SIGNAL Go")));
  await shot(page, "tree");
});

test("the map marks drops and signals' positions, keeps whole trails, never overlaps names, and shows the world the editor opens after a flight", async () => {
  const page = await open(chromium, station);
  await choose(page, "parcel_delivery.mission");
  await page.fill("#speed", "50");
  await page.click("#fly");
  await page.waitForFunction(() => window.aviary.model.mission === "Parcel_Delivery" && window.aviary.model.status === "ok", null, { timeout: 120000 });
  await page.waitForTimeout(300);
  // Back at the depot, side by side: one label for the couriers close together.
  const labels = await page.evaluate(() => window.aviary.map.labels);
  assert.ok(labels.some((l) => /^courier\d \+\d$/.test(l)), `labels at the depot: ${labels}`);
  const seen = await page.evaluate(() => ({
    spots: window.aviary.model.spots.map((s) => [s.kind, s.text]),
    drops: window.aviary.map.findLayer.getLayers().filter((l) => l.options.className === "spot-drop").length,
    signals: window.aviary.map.findLayer.getLayers().filter((l) => l.options.className === "spot-signal").length,
    trail: window.aviary.model.drones.get("courier4").trail,
  }));
  // Two parcels released, each marked where it fell; the stranded parcel's signal, where
  // its destination is.
  assert.deepEqual(seen.spots.filter((s) => s[0] === "drop").map((s) => s[1]), ["payload dropped by courier2", "payload dropped by courier4"]);
  assert.equal(seen.drops, 2);
  assert.ok(seen.spots.some((s) => s[0] === "signal" && s[1] === "Parcel_Stranded from courier1"), JSON.stringify(seen.spots));
  assert.ok(seen.signals >= 1);
  // courier4 flew some 300 s at 4 samples a second: its trail still starts at its home.
  const [x, y] = seen.trail[0];
  assert.ok(Math.hypot(x - 30, y) < 5, `the trail starts at (${x}, ${y})`);
  assert.ok(seen.trail.length <= 360, `thinned, not grown without end: ${seen.trail.length}`);
  await shot(page, "marks");
  // Another mission opened after the flight: its world on the map, the old drones gone.
  await page.selectOption("#mission-file", "lost_hiker.mission");
  await page.waitForFunction(() => window.aviary.editor.files.world.path === "lost_hiker.world.toml" && document.getElementById("check-summary").classList.contains("good"));
  await page.waitForTimeout(300);
  const after = await page.evaluate(() => ({
    names: window.aviary.map.world.getLayers().map((l) => l.getTooltip && l.getTooltip() && l.getTooltip().getContent()).filter(Boolean),
    drones: window.aviary.model.drones.size,
  }));
  assert.ok(after.names.includes("Hut") && !after.names.includes("Depot"), `the map shows: ${after.names}`);
  assert.equal(after.drones, 0, "the finished flight's drones are gone from the map");
});
