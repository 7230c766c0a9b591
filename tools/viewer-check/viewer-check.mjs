// Loads taiga's web viewer in headless Chromium (Debian's /usr/bin/chromium, WebGL in software)
// and prints one JSON object: the page's console errors and uncaught exceptions, its counters
// (window.taigaView: mode, points shown, poses, keyframes, scans), and how many pixels of the 3D
// view differ from the background; writes a screenshot. Retries loading until the server is up.
// Usage: node viewer-check.mjs URL SCREENSHOT.png [TIMEOUT_S]
import { chromium } from "playwright-core";

const [url, screenshot] = process.argv.slice(2, 4);
const timeoutS = Number(process.argv[4] ?? 60);
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
} catch (e) {
  result.error = String(e);
} finally {
  await browser.close();
}
process.stdout.write(JSON.stringify(result) + "\n");
