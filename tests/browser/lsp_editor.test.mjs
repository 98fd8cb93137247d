// The station's editor speaks to the language server of `aviary lsp` (over `/api/lsp`):
// an operator types an error into the paper's mission and sees it marked as they type,
// starts a place's name and picks it from the completion list, hovers a capability and
// reads its signature; the world file is checked by the same server; a capability of a
// USEd file is read from the disk as `aviary lsp` reads it.

import { test, before, after } from "node:test";
import assert from "node:assert/strict";
import { mkdirSync, mkdtempSync, writeFileSync } from "node:fs";
import { tmpdir } from "node:os";
import { join } from "node:path";
import { browser, choose, examples, open, shot, start } from "./harness.mjs";

let station, chromium;

before(async () => {
  station = await start(["gcs", examples(), "--listen", "0"]);
  chromium = await browser();
});

after(async () => {
  await chromium?.close();
  station?.process.kill("SIGTERM");
});

/// Where the text `needle` starts in the file shown, `plus` characters on, on the screen.
async function at(page, needle, plus = 0) {
  return page.evaluate(({ needle, plus }) => {
    const view = window.aviary.editor.view;
    const pos = view.state.doc.toString().indexOf(needle);
    if (pos < 0) return null;
    const c = view.coordsAtPos(pos + plus);
    return c && { x: c.left + 2, y: (c.top + c.bottom) / 2 };
  }, { needle, plus });
}

test("the editor marks a typed error, completes a place and shows a capability's signature", async () => {
  const page = await open(chromium, station);
  await choose(page, "search_and_rescue.mission");
  // The token was given after the page opened: the editor asks for the server when the
  // operator clicks into it.
  const line = page.locator(".editor-file[data-file=mission] .cm-line", { hasText: "video_drone1 FlyTo WITH BuildingA" });
  await line.click();
  await page.waitForFunction(() => window.aviary.editor.server.state === "on");
  assert.equal(await page.textContent("#lsp-status"), "language server: on");
  // At the line's end, the place becomes one the world does not have.
  await page.keyboard.press("End");
  for (let i = 0; i < "BuildingA".length; i++) await page.keyboard.press("Backspace");
  await page.keyboard.type("Nowhere");
  const error = page.locator(".editor-file[data-file=mission] .cm-lintRange-error", { hasText: "Nowhere" });
  await error.waitFor();
  await page.waitForSelector(".editor-file[data-file=mission] .cm-gutter-lint .cm-lint-marker-error");
  assert.ok(await page.evaluate(() => window.aviary.editor.files.mission.dirty), "the file is changed");
  assert.match(await page.evaluate(() => window.aviary.editor.files.mission.text), /video_drone1 FlyTo WITH Nowhere/);
  // The error's message, as the server says it, on hovering the mark.
  const marked = await at(page, "WITH Nowhere", 6);
  await page.mouse.move(marked.x, marked.y);
  const lint = await page.waitForSelector(".cm-tooltip-lint");
  assert.match(await lint.textContent(), /Nowhere/);
  await page.mouse.move(5, 5);

  // The start of a place's name: the server's completion offers the world's places.
  for (let i = 0; i < "Nowhere".length; i++) await page.keyboard.press("Backspace");
  await page.keyboard.type("Buil");
  const list = await page.waitForSelector(".cm-tooltip-autocomplete");
  await page.waitForSelector(".cm-tooltip-autocomplete li:has-text('BuildingB')");
  const offered = await list.$$eval("li", (items) => items.map((li) => li.textContent));
  assert.ok(offered.some((t) => t.includes("BuildingA")), `offered: ${offered.join(", ")}`);
  await shot(page, "station-editor");
  // Picking one puts it in the text, and the error goes.
  await page.click(".cm-tooltip-autocomplete li:has-text('BuildingA')");
  await page.waitForFunction(() => /video_drone1 FlyTo WITH BuildingA\n/.test(window.aviary.editor.files.mission.text));
  await page.waitForFunction(() => !document.querySelector(".editor-file[data-file=mission] .cm-lintRange-error"));

  // Hovering a capability shows its signature.
  const capability = await at(page, "FlyTo WITH BuildingA", 2);
  await page.mouse.move(capability.x, capability.y);
  const hover = await page.waitForSelector(".cm-tooltip-hover");
  const shown = await hover.textContent();
  assert.match(shown, /FlyTo/);
  assert.match(shown, /\(/, `a signature: ${shown}`);
  await shot(page, "station-editor-hover");
  assert.deepEqual(page.foreign, [], "the page loaded nothing from elsewhere");
  await page.close();
});

test("the world file is edited in the same editor and checked by the same server", async () => {
  const page = await open(chromium, station);
  await choose(page, "search_and_rescue.mission");
  await page.click("#edit-world");
  const world = page.locator(".editor-file[data-file=world] .cm-line", { hasText: /^\[site\]/ });
  await world.click();
  await page.waitForFunction(() => window.aviary.editor.server.state === "on");
  await page.keyboard.press("End");
  await page.keyboard.type("x");
  await page.waitForSelector(".editor-file[data-file=world] .cm-lint-marker-error");
  assert.ok(await page.evaluate(() => window.aviary.editor.files.world.dirty));
  assert.ok(!(await page.evaluate(() => window.aviary.editor.files.mission.dirty)));
  // Undone, the world is whole again.
  await page.keyboard.press("Backspace");
  await page.waitForFunction(() => !document.querySelector(".editor-file[data-file=world] .cm-lint-marker-error"));
  await page.close();
});

test("a capability of a USEd file is found on the station's disk, as aviary lsp finds it", async () => {
  const dir = mkdtempSync(join(tmpdir(), "aviary-gcs-use-"));
  mkdirSync(join(dir, "lib"));
  writeFileSync(join(dir, "site.world.toml"), "[places]\nHome = [0, 0]\n\n[drones.scout]\nhome = [0, 0]\n");
  writeFileSync(join(dir, "lib/moves.mission"),
    "// Back to the place called Home.\nCAPABILITY GoHome BY drone:\n    PERFORM:\n        drone FlyTo WITH Home\n");
  writeFileSync(join(dir, "site.mission"), 'USE "lib/moves.mission"\n\nMISSION Site:\n    scout TakeOff\n    scout GoHome\n');
  const own = await start(["gcs", dir, "--listen", "0"]);
  try {
    const page = await open(chromium, own);
    await choose(page, "site.mission");
    await page.locator(".editor-file[data-file=mission] .cm-line", { hasText: "scout GoHome" }).click();
    await page.waitForFunction(() => window.aviary.editor.server.state === "on");
    const used = await at(page, "GoHome", 2);
    await page.mouse.move(used.x, used.y);
    const hover = await page.waitForSelector(".cm-tooltip-hover");
    assert.match(await hover.textContent(), /GoHome BY drone/);
    assert.equal(await page.$(".editor-file[data-file=mission] .cm-lintRange-error"), null, "the USE is found");
    await page.mouse.move(5, 5);
    // A capability no file has is marked as typed.
    await page.keyboard.press("End");
    await page.keyboard.type("x");
    await page.waitForSelector(".editor-file[data-file=mission] .cm-lintRange-error");
    await page.close();
  } finally {
    own.process.kill("SIGTERM");
  }
});

test("what the server's Markdown holds reaches the page as text, but for plain elements", async () => {
  const page = await open(chromium, station);
  const shown = await page.evaluate(async () => {
    const { sanitize } = await import("/assets/js/lsp.js");
    return sanitize('<p onclick="x()">a <em>b</em></p><img src=x onerror="alert(1)"><script>alert(2)</script>' +
      '<a href="javascript:alert(3)">c</a><a href="https://example.org/">d</a><iframe src="/"></iframe>');
  });
  assert.equal(shown, '<p>a <em>b</em></p>alert(2)<a>c</a><a href="https://example.org/">d</a>');
  await page.close();
});

test("without the token the editor has no server until the operator gives it; a wrong one is refused", async () => {
  const page = await open(chromium, station, { token: false });
  await choose(page, "search_and_rescue.mission");
  await page.click(".editor-file[data-file=mission] .cm-content");
  assert.equal(await page.textContent("#lsp-status"), "language server: give the token (click)");
  await page.evaluate(() => sessionStorage.setItem("aviary.token", "0123456789abcdef0123456789abcdef"));
  await page.click(".editor-file[data-file=mission] .cm-content");
  await page.waitForFunction(() => window.aviary.editor.server.state === "refused");
  // A click on the note asks for the token; the right one connects.
  await page.click("#lsp-status");
  await page.fill("#token-input", station.token);
  await page.click("#token-dialog button[value=ok]");
  await page.waitForFunction(() => window.aviary.editor.server.state === "on");
  await page.waitForSelector(".editor-file[data-file=mission] .cm-gutter-lint");
  await page.close();
});
