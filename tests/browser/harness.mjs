// What the browser tests share: the real `aviary` started on a free loopback port, and
// Debian's Chromium, headless, driven by playwright-core. Screenshots go to
// target/screenshots/, or, with UPDATE_SCREENSHOTS=1, to docs/gcs/, which docs/GCS.md
// shows: a test run leaves the repository as it was.

import { spawn } from "node:child_process";
import { cpSync, mkdtempSync, mkdirSync, readFileSync, writeFileSync } from "node:fs";
import { tmpdir } from "node:os";
import { dirname, join, resolve } from "node:path";
import { fileURLToPath } from "node:url";
import { chromium } from "playwright-core";

export const ROOT = resolve(dirname(fileURLToPath(import.meta.url)), "../..");
export const AVIARY = process.env.AVIARY_BIN || join(ROOT, "target/debug/aviary");
export const SHOTS = process.env.UPDATE_SCREENSHOTS ? join(ROOT, "docs/gcs") : join(ROOT, "target/screenshots");

/// A copy of the examples and of the tests' own missions (`fixtures/`), so that a test may
/// edit and save without touching the repository.
export function examples() {
  const dir = mkdtempSync(join(tmpdir(), "aviary-gcs-"));
  cpSync(join(ROOT, "examples"), dir, { recursive: true });
  cpSync(join(ROOT, "tests/browser/fixtures"), join(dir, "drills"), { recursive: true });
  return dir;
}

/// Opens `mission` (and the world beside it) in the page, and waits for its check.
export async function choose(page, mission) {
  await page.waitForSelector("#mission-file option", { state: "attached" });
  await page.selectOption("#mission-file", mission);
  await page.waitForFunction((m) => window.aviary.checked && window.aviary.editor.files.mission.path === m &&
    document.getElementById("check-summary").classList.contains("good"), mission);
}

/// A drone's position as the page has it.
export function position(page, name) {
  return page.evaluate((n) => window.aviary.model.drones.get(n)?.pos, name);
}

/// Starts `aviary ARGS...` and waits for the line that says where the station is and its
/// token. Resolves to {url, token, process, output}.
export function start(args) {
  return new Promise((resolveStart, reject) => {
    const child = spawn(AVIARY, args, { stdio: ["ignore", "pipe", "pipe"] });
    let output = "";
    const timer = setTimeout(() => reject(new Error(`aviary did not start: ${output}`)), 60000);
    const seen = (chunk) => {
      output += chunk.toString();
      const token = output.match(/operator API on \S+\s+token ([0-9a-f]+)/);
      const page = output.match(/ground station on (http:\/\/\S+?)\/?\s/);
      if (token && page) {
        clearTimeout(timer);
        resolveStart({ url: page[1], token: token[1], process: child, output: () => output });
      }
    };
    child.stderr.on("data", seen);
    child.stdout.on("data", (c) => { output += c.toString(); });
    child.on("exit", (code) => {
      clearTimeout(timer);
      reject(new Error(`aviary exited ${code}: ${output}`));
    });
  });
}

export async function browser() {
  return chromium.launch({
    executablePath: process.env.CHROMIUM || "/usr/bin/chromium",
    headless: true,
    args: ["--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run",
      "--disable-background-networking", "--disable-component-update", "--disable-sync"],
  });
}

/// A page of the station, with its token given once as an operator gives it.
export async function open(b, station, { token = true } = {}) {
  const context = await b.newContext({ viewport: { width: 1600, height: 1000 } });
  const page = await context.newPage();
  page.on("pageerror", (e) => { throw e; });
  // Every request the page makes must go to the station: nothing from the internet.
  const foreign = [];
  page.on("request", (r) => { if (!r.url().startsWith(station.url)) foreign.push(r.url()); });
  page.foreign = foreign;
  await page.goto(station.url + "/");
  if (token) await page.evaluate((t) => sessionStorage.setItem("aviary.token", t), station.token);
  return page;
}

export async function shot(page, name) {
  mkdirSync(SHOTS, { recursive: true });
  await page.screenshot({ path: join(SHOTS, `${name}.png`) });
}

/// Starts `aviary vehicles` (the project's own MAVLink vehicles, here at 10 times real
/// time) on a free loopback port; resolves to {port, child}.
function serveVehicles(world) {
  return new Promise((resolve, reject) => {
    const child = spawn(AVIARY, ["vehicles", "--world", world, "--listen", "tcp:127.0.0.1:0", "--speed", "10"],
      { stdio: ["ignore", "pipe", "ignore"] });
    let out = "";
    child.stdout.on("data", (c) => {
      out += c.toString();
      const m = out.match(/127\.0\.0\.1:(\d+)/);
      if (m) resolve({ port: Number(m[1]), child });
    });
    child.on("exit", (code) => reject(new Error(`aviary vehicles exited ${code}: ${out}`)));
  });
}

/// A folder with the tests' missions (`fixtures/`) whose patrol flies three MAVLink drones
/// of `aviary vehicles`: the vehicles' own world is the patrol's, changed by `vehicleWorld`
/// (their figures), placed at an origin. Resolves to {dir, vehicles} (the process).
export async function mavlinkPatrol(prefix, vehicleWorld = (w) => w) {
  const dir = mkdtempSync(join(tmpdir(), prefix));
  cpSync(join(ROOT, "tests/browser/fixtures"), dir, { recursive: true });
  const origin = "origin = { lat = 46.6167, lon = 14.2650, alt = 440.0 }\n";
  const plain = readFileSync(join(dir, "patrol.world.toml"), "utf8").replace("[site]\n", `[site]\n${origin}`);
  writeFileSync(join(dir, "vehicles.world.toml.txt"), vehicleWorld(plain));
  const { port, child } = await serveVehicles(join(dir, "vehicles.world.toml.txt"));
  let bound = plain;
  for (const d of ["scout", "carrier", "spare"])
    bound = bound.replace(`[drones.${d}]\n`, `[drones.${d}]\nmavlink = "tcp:127.0.0.1:${port}"\n`);
  writeFileSync(join(dir, "patrol.world.toml"), bound);
  return { dir, vehicles: child };
}
