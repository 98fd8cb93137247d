// The station of a run on another machine (`aviary gcs --zenoh`): a run publishes itself
// on Zenoh, two stations reach it there, each with its page. A pause from one page is seen
// on the other within a second; a station without the run's token only watches.

import { test, before, after } from "node:test";
import assert from "node:assert/strict";
import { spawn } from "node:child_process";
import { cpSync, mkdtempSync, writeFileSync } from "node:fs";
import { createServer } from "node:net";
import { tmpdir } from "node:os";
import { join } from "node:path";
import { AVIARY, ROOT, browser, open, shot, start } from "./harness.mjs";

const PREFIX = "aviary/remote_test";
let run, stations = [], watcher, chromium;

/// A free TCP port on loopback.
function freePort() {
  return new Promise((resolve) => {
    const server = createServer();
    server.listen(0, "127.0.0.1", () => {
      const { port } = server.address();
      server.close(() => resolve(port));
    });
  });
}

/// A Zenoh peer that listens or connects (`role`) at `endpoint` only, and scouts for no one.
const peer = (role, endpoint) =>
  `{ mode: "peer", ${role}: { endpoints: ["${endpoint}"] }, scouting: { multicast: { enabled: false }, gossip: { enabled: false } } }`;

/// `aviary run` of the patrol on Zenoh; resolves to {process, token, output} once it says
/// where it is.
function startRun(dir) {
  return new Promise((resolve, reject) => {
    const child = spawn(AVIARY, ["run", "patrol.mission", "--zenoh", "run.json5", "--zenoh-prefix", PREFIX,
      "--speed", "4", "--trace", "t.jsonl", "--quiet"], { cwd: dir, stdio: ["ignore", "ignore", "pipe"] });
    let output = "";
    child.stderr.on("data", (c) => {
      output += c.toString();
      const m = output.match(/on Zenoh under \S+ .*token ([0-9a-f]+)/);
      if (m) resolve({ process: child, token: m[1], output: () => output });
    });
    child.on("exit", (code) => reject(new Error(`aviary run exited ${code}: ${output}`)));
  });
}

before(async () => {
  const dir = mkdtempSync(join(tmpdir(), "aviary-remote-"));
  cpSync(join(ROOT, "tests/browser/fixtures"), dir, { recursive: true });
  const endpoint = `tcp/127.0.0.1:${await freePort()}`;
  writeFileSync(join(dir, "run.json5"), peer("listen", endpoint));
  writeFileSync(join(dir, "station.json5"), peer("connect", endpoint));
  run = await startRun(dir);
  const station = (token) => start(["gcs", "--zenoh", join(dir, "station.json5"), "--zenoh-prefix", PREFIX,
    "--listen", "0", ...(token ? ["--token", token] : [])]);
  stations = [await station(run.token), await station(run.token)];
  watcher = await station(null);
  chromium = await browser();
});

after(async () => {
  await chromium?.close();
  for (const s of [...stations, watcher]) s?.process.kill("SIGTERM");
  run?.process.kill("SIGTERM");
});

test("two stations of a run on Zenoh: a pause from one is seen on the other within a second", async () => {
  const [a, b] = await Promise.all(stations.map((s) => open(chromium, s)));
  for (const page of [a, b]) {
    await page.waitForFunction(() => window.aviary.model.status === "running", null, { timeout: 30000 });
    await page.waitForFunction(() => window.aviary.model.drones.size === 3);
    await page.waitForFunction(() => [...window.aviary.model.drones.values()].some((d) => d.trail.length > 3));
  }
  await a.click("#pause");
  const clicked = Date.now();
  await b.waitForFunction(() => window.aviary.model.paused === true, null, { timeout: 5000 });
  const seen = Date.now() - clicked;
  assert.ok(seen <= 1000, `the other station shows the pause ${seen} ms after the click`);
  await a.waitForFunction(() => window.aviary.model.paused === true);
  // Drawn: the tree shows the running activities held.
  await b.waitForFunction(() => document.querySelector("#tree .node[data-status=paused]") !== null);
  await shot(b, "remote-paused");
  await b.click("#resume");
  await a.waitForFunction(() => window.aviary.model.paused === false, null, { timeout: 1000 });
  // The page's calls went to the run: it says so in its own trace, and nothing came from
  // the internet.
  for (const page of [a, b]) assert.deepEqual(page.foreign, []);
});

test("a station without the run's token watches, and is refused a control call with the reason", async () => {
  const page = await open(chromium, watcher);
  await page.waitForFunction(() => window.aviary.model.drones.size === 3, null, { timeout: 30000 });
  const refused = await page.evaluate(async (token) => {
    const r = await fetch("/api/pause", { method: "POST", headers: { Authorization: `Bearer ${token}` } });
    return { status: r.status, body: await r.json() };
  }, watcher.token);
  assert.equal(refused.status, 403);
  assert.match(refused.body.error, /only watches: start `aviary gcs --zenoh` with `--token`/);
});
