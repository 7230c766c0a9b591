// Loads taiga's web viewer in headless Chromium (Debian's /usr/bin/chromium, WebGL in software)
// and prints one JSON object: the page's console errors and uncaught exceptions, its counters
// (window.taigaView: mode, points shown, poses, keyframes, scans), and how many pixels of the 3D
// view differ from the background; writes a screenshot. Retries loading until the server is up.
// With --orbit, it then drags the view around for 5 s as a user would and reports the frames
// drawn per second, the points shown and the node bytes fetched (bench/viewer.sh).
// With --min-keyframes N, a live page is judged once N keyframes arrived, not at its first: how
// much of the view the map covers must not depend on when Chromium happened to connect.
// Usage: node viewer-check.mjs URL SCREENSHOT.png [TIMEOUT_S] [--orbit] [--min-keyframes N]
import { chromium } from "playwright-core";

const [url, screenshot] = process.argv.slice(2, 4);
const timeoutS = Number(process.argv[4] ?? 60);
const orbit = process.argv.includes("--orbit");
const minKeyframesAt = process.argv.indexOf("--min-keyframes");
const minKeyframes = minKeyframesAt > 0 ? Number(process.argv[minKeyframesAt + 1]) : 0;
const deadline = Date.now() + timeoutS * 1000;

const browser = await chromium.launch({
  executablePath: process.env.CHROMIUM ?? "/usr/bin/chromium",
  args: ["--no-sandbox", "--use-angle=swiftshader", "--enable-unsafe-swiftshader"],
});
const result = { consoleErrors: [], pageErrors: [], loaded: false, ready: false };
try {
  const page = await browser.newPage({ viewport: { width: 1280, height: 800 } });
  page.on("console", (m) => { if (m.type() === "error") result.consoleErrors.push(m.text()); });
  page.on("pageerror", (e) => result.pageErrors.push(String(e)));
  while (!result.loaded) {
    try {
      await page.goto(url, { timeout: 10000 });
      result.loaded = true;
    } catch (e) {
      if (Date.now() > deadline) throw e;
      await new Promise((r) => setTimeout(r, 250));
    }
  }
  // Ready: data arrived and is drawn. Then what the level of detail asks for is fetched.
  await page.waitForFunction(() => window.taigaView?.ready === true, null,
                             { timeout: Math.max(deadline - Date.now(), 1000) });
  result.ready = true;
  await page.waitForFunction((n) => window.taigaView.keyframes >= n, minKeyframes,
                             { timeout: Math.max(deadline - Date.now(), 1000) });
  await page.waitForFunction(() => window.taigaView.loading === 0, null, { timeout: 20000 });
  await page.waitForTimeout(500);
  result.state = await page.evaluate(() => ({ ...window.taigaView }));
  // Pixels of the 3D view that are not the background (the WebGL canvas keeps its drawing).
  result.litPixels = await page.evaluate(() => {
    const source = document.getElementById("view");
    const copy = document.createElement("canvas");
    copy.width = source.width; copy.height = source.height;
    const g = copy.getContext("2d");
    g.drawImage(source, 0, 0);
    const data = g.getImageData(0, 0, copy.width, copy.height).data;
    let lit = 0;
    for (let i = 0; i < data.length; i += 4)
      if (Math.abs(data[i] - 0x10) + Math.abs(data[i + 1] - 0x16) + Math.abs(data[i + 2] - 0x1c) > 30) ++lit;
    return { lit, of: data.length / 4 };
  });
  await page.screenshot({ path: screenshot });
  if (orbit) result.orbit = await dragAround(page);
} catch (e) {
  result.error = String(e);
} finally {
  await browser.close();
}
process.stdout.write(JSON.stringify(result) + "\n");

/// Drags the view in a circle for 5 s (OrbitControls turns it), then lets the detail load.
async function dragAround(page) {
  const before = await page.evaluate(() => window.taigaView.frames);
  const start = Date.now();
  await page.mouse.move(640, 400);
  await page.mouse.down();
  let maxShown = 0;
  for (let i = 0; Date.now() - start < 5000; ++i) {
    await page.mouse.move(640 + 200 * Math.cos(i / 20), 400 + 60 * Math.sin(i / 20), { steps: 2 });
    maxShown = Math.max(maxShown, await page.evaluate(() => window.taigaView.pointsShown));
  }
  await page.mouse.up();
  const seconds = (Date.now() - start) / 1000;
  const frames = (await page.evaluate(() => window.taigaView.frames)) - before;
  await page.waitForFunction(() => window.taigaView.loading === 0, null, { timeout: 60000 });
  const fetched = await page.evaluate(() => performance.getEntriesByType("resource")
    .filter((e) => e.name.includes("/api/node/"))
    .reduce((sum, e) => ({ nodes: sum.nodes + 1, bytes: sum.bytes + e.encodedBodySize }), { nodes: 0, bytes: 0 }));
  return { seconds, frames, fps: frames / seconds, maxPointsShown: maxShown, fetched };
}
