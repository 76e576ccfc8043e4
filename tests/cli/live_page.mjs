// Drives the live page of `pspslam run --viewer --viewer-paused` in headless chromium
// (playwright-core from web/node_modules, Debian's /usr/bin/chromium) and prints what it saw as
// one JSON line; test_cli (live_viewer_test.cpp) asserts on it.
// Usage: node live_page.mjs PLAYWRIGHT_CORE_DIR URL SCREENSHOT.png
const [playwrightDir, url, screenshot] = process.argv.slice(2);
const { chromium } = await import(`${playwrightDir}/index.mjs`);

const seen = {};
const browser = await chromium.launch({
  executablePath: '/usr/bin/chromium',
  // Software WebGL; no proxy for the local server; root in CI needs --no-sandbox.
  args: ['--no-sandbox', '--no-proxy-server', '--enable-unsafe-swiftshader'],
});
const data = (page) => page.evaluate(() => ({ ...document.body.dataset }));
const sleep = (ms) => new Promise((resolve) => setTimeout(resolve, ms));
// Held: the run loop waits after the frame the page shows.
const held = `document.body.dataset.runState === 'paused' &&
              document.body.dataset.frame === document.body.dataset.heldFrame`;
try {
  const page = await browser.newPage({ viewport: { width: 1400, height: 900 } });
  page.on('pageerror', (error) => { seen.page_error = String(error); });
  await page.goto(url);
  await page.waitForFunction(held, null, { timeout: 60000 });
  seen.start = Number((await data(page)).frame);
  await sleep(1500);
  seen.start_later = Number((await data(page)).frame);

  await page.click('#step');
  await page.waitForFunction(`${held} && Number(document.body.dataset.frame) > ${seen.start}`,
                             null, { timeout: 60000 });
  seen.step = Number((await data(page)).frame);
  await sleep(1500);
  seen.step_later = Number((await data(page)).frame);

  await page.click('#resume');
  await page.waitForFunction(`Number(document.body.dataset.mapPoints) > 0 &&
                              Number(document.body.dataset.keyframes) >= 2 &&
                              Number(document.body.dataset.dynamicSeen) > 0`,
                             null, { timeout: 240000 });
  await page.click('#pause');
  await page.waitForFunction(held, null, { timeout: 60000 });
  const paused = await data(page);
  seen.map_points = Number(paused.mapPoints);
  seen.keyframes = Number(paused.keyframes);
  seen.dynamic_seen = Number(paused.dynamicSeen);
  seen.paused = Number(paused.frame);
  await sleep(2000);
  seen.paused_later = Number((await data(page)).frame);
  await page.screenshot({ path: screenshot });

  await page.click('#step');
  await page.waitForFunction(`${held} && Number(document.body.dataset.frame) > ${seen.paused}`,
                             null, { timeout: 60000 });
  seen.paused_step = Number((await data(page)).frame);
  await page.click('#resume');
  await page.waitForFunction(`document.body.dataset.runState === 'finished'`, null,
                             { timeout: 300000 });
  seen.finished = true;
} catch (error) {
  seen.error = String(error);
} finally {
  await browser.close();
}
console.log(JSON.stringify(seen));
