// Drives headless Chromium over the DevTools protocol (a pipe: fds 3 and 4, NUL-separated
// JSON) and prints the frames per second of each page given as an argument, measured over
// `SECONDS` after a warm-up. Each argument is NAME=URL; the page must expose its frame count
// (three.html: `frames_drawn`; lightgrid's page: `status().frames`).
// Usage: node measure.mjs SECONDS NAME=URL...
import { spawn } from "node:child_process";
import { mkdtempSync } from "node:fs";
import { tmpdir } from "node:os";
import { join } from "node:path";

const seconds = Number(process.argv[2]);
const pages = process.argv.slice(3).map((a) => a.split(/=(.*)/s).slice(0, 2));
const chrome = spawn(process.env.CHROMIUM || "chromium", [
  "--headless=new", "--no-sandbox", "--enable-unsafe-webgpu", "--use-vulkan=swiftshader",
  "--enable-features=Vulkan", "--use-angle=vulkan", "--remote-debugging-pipe",
  "--no-first-run", "--disable-background-networking", "--disable-component-update",
  "--disable-sync", "--disable-default-apps", "--window-size=1000,800",
  "--force-device-scale-factor=1", `--user-data-dir=${mkdtempSync(join(tmpdir(), "lg-cmp-"))}`,
], { stdio: ["ignore", "ignore", "ignore", "pipe", "pipe"] });
const [input, output] = [chrome.stdio[3], chrome.stdio[4]];
let next = 1, pending = new Map(), buffered = "";
output.on("data", (chunk) => {
  buffered += chunk.toString();
  let end;
  while ((end = buffered.indexOf("\0")) >= 0) {
    const message = JSON.parse(buffered.slice(0, end));
    buffered = buffered.slice(end + 1);
    if (message.id && pending.has(message.id)) {
      pending.get(message.id)(message);
      pending.delete(message.id);
    }
  }
});
const call = (method, params = {}, sessionId) => new Promise((resolve, reject) => {
  const id = next++;
  pending.set(id, (m) => (m.error ? reject(new Error(`${method}: ${m.error.message}`)) : resolve(m.result)));
  input.write(JSON.stringify({ id, method, params, sessionId }) + "\0");
});
const sleep = (ms) => new Promise((r) => setTimeout(r, ms));

const FRAMES = `(() => { if (window.failed) return "failed: " + window.failed;
  if (window.lightgrid && window.lightgridStarted) {
    const f = window.lightgrid.fatal(); if (f) return "failed: " + f;
    const s = JSON.parse(window.lightgrid.status());
    return s.message === "" && s.pending === false && s.settled >= 2 && s.scene.startsWith("lights-") ? s.frames : null;
  }
  if (window.lightgridStarted === false) return "failed: " + document.getElementById("error").textContent;
  return window.ready ? window.frames_drawn : null; })()`;

const results = [];
for (const [name, url] of pages) {
  const { targetId } = await call("Target.createTarget", { url: "about:blank" });
  const { sessionId } = await call("Target.attachToTarget", { targetId, flatten: true });
  await call("Page.navigate", { url }, sessionId);
  const frames = async () => (await call("Runtime.evaluate", { expression: FRAMES, returnByValue: true }, sessionId)).result.value;
  const deadline = Date.now() + 240_000;
  let f;
  while (typeof (f = await frames()) !== "number") {
    if (typeof f === "string") throw new Error(`${name}: ${f}`);
    if (Date.now() > deadline) throw new Error(`${name}: never ready`);
    await sleep(200);
  }
  await sleep(3000); // warm-up
  const [f0, t0] = [await frames(), performance.now()];
  await sleep(seconds * 1000);
  const [f1, t1] = [await frames(), performance.now()];
  const fps = ((f1 - f0) * 1000) / (t1 - t0);
  results.push({ name, fps: Number(fps.toFixed(2)), frames: f1 - f0 });
  console.log(`${name}: ${fps.toFixed(2)} fps (${f1 - f0} frames in ${((t1 - t0) / 1000).toFixed(1)} s)`);
  await call("Target.closeTarget", { targetId });
}
console.log(JSON.stringify(results));
chrome.kill();
process.exit(0);
