// Screenshots of the live page of `pspslam run --viewer 127.0.0.1:PORT --viewer-paused` at a
// chosen frame (the README's pictures): runs the held run up to FRAME, pauses, turns the ant
// path on, saves the whole page and the frame view, then lets the run go on.
// Usage: node tools/viewer/live_screenshot.mjs URL FRAME PAGE.png FRAME_VIEW.png
//        (playwright-core from web/node_modules, chromium from Debian)
import path from 'node:path';
import { fileURLToPath } from 'node:url';
const [url, frame, pageShot, frameShot] = process.argv.slice(2);
const web = path.resolve(path.dirname(fileURLToPath(import.meta.url)), '../../web');
const { chromium } = await import(`${web}/node_modules/playwright-core/index.mjs`);

const browser = await chromium.launch({
  executablePath: '/usr/bin/chromium',
  args: ['--no-sandbox', '--no-proxy-server', '--enable-unsafe-swiftshader'],
});
const held = `document.body.dataset.runState === 'paused' &&
              document.body.dataset.frame === document.body.dataset.heldFrame`;
try {
  const page = await browser.newPage({ viewport: { width: 1500, height: 1000 } });
  await page.goto(url);
  await page.waitForFunction(held, null, { timeout: 120000 });
  await page.click('#resume');
  await page.waitForFunction(`Number(document.body.dataset.frame) >= ${Number(frame) - 1}`, null,
                             { timeout: 600000, polling: 50 });
  await page.click('#pause');
  await page.waitForFunction(held, null, { timeout: 120000 });
  await page.check('#show-search');
  await page.waitForTimeout(1500);  // the images of the held frame
  await page.screenshot({ path: pageShot });
  await page.locator('#frame-view').screenshot({ path: frameShot });
  console.log(`held at frame ${await page.evaluate(() => document.body.dataset.frame)}`);
  await page.click('#resume');
} finally {
  await browser.close();
}
