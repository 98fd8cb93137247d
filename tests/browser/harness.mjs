// What the browser tests share: the real `aviary` started on a free loopback port, and
// Debian's Chromium, headless, driven by playwright-core. Screenshots go to docs/gcs/,
// which docs/GCS.md shows.

import { spawn } from "node:child_process";
import { cpSync, mkdtempSync, mkdirSync } from "node:fs";
import { tmpdir } from "node:os";
import { dirname, join, resolve } from "node:path";
import { fileURLToPath } from "node:url";
import { chromium } from "playwright-core";

export const ROOT = resolve(dirname(fileURLToPath(import.meta.url)), "../..");
export const AVIARY = process.env.AVIARY_BIN || join(ROOT, "target/debug/aviary");
export const SHOTS = join(ROOT, "docs/gcs");

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
