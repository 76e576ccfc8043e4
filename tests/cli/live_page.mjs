// Drives the live page of `pspslam run --viewer --viewer-paused` in headless chromium
// (playwright-core from web/node_modules, Debian's /usr/bin/chromium) and prints what it saw as
// one JSON line; test_cli (test_live_viewer.cpp) asserts on it. CHECK: `controls` (the default:
// pause, step, toggles), `atlas` (run to the end, the maps listed) or `people` (run to the end,
// the people drawn and labelled, the occupancy toggle's state) or `occupancy` (--occupancy: the
// grid layer shown and its cells).
// Usage: node live_page.mjs PLAYWRIGHT_CORE_DIR URL SCREENSHOT.png [CHECK]
const [playwrightDir, url, screenshot, check = 'controls'] = process.argv.slice(2);
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
// 3D view: pixels of one colour (within 2 per channel) in the WebGL canvas. The lines are drawn
// in their exact colour (measured: the same count at 2 as at 24); a looser match also counted
// the odd blend of other layers (CI: 2 "green" pixels with the edges off).
const colourPixels = (page, rgb) => page.evaluate((rgb) => {
  const gl = document.querySelector('#scene canvas');
  const copy = document.createElement('canvas');
  copy.width = gl.width;
  copy.height = gl.height;
  const g = copy.getContext('2d');
  g.drawImage(gl, 0, 0);
  const pixels = g.getImageData(0, 0, copy.width, copy.height).data;
  let count = 0;
  for (let i = 0; i < pixels.length; i += 4) {
    count += Math.abs(pixels[i] - rgb[0]) <= 2 && Math.abs(pixels[i + 1] - rgb[1]) <= 2 &&
             Math.abs(pixels[i + 2] - rgb[2]) <= 2;
  }
  return count;
}, rgb);
const settle = () => sleep(400);  // a change is drawn on the next animation frame

// Held at the start, stepped, run, paused: the controls and the toggles.
async function pauseStepAndToggles(page) {
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
  // Far enough that the trajectory and the edges span more than a few pixels of the 3D view.
  await page.waitForFunction(`Number(document.body.dataset.frame) >= 60 &&
                              Number(document.body.dataset.mapPoints) > 0 &&
                              Number(document.body.dataset.keyframes) >= 2 &&
                              Number(document.body.dataset.dynamicSeen) > 0 &&
                              Number(document.body.dataset.covisibilityEdges) > 0`,
                             null, { timeout: 240000 });
  await page.click('#pause');
  await page.waitForFunction(held, null, { timeout: 60000 });
  const paused = await data(page);
  seen.map_points = Number(paused.mapPoints);
  seen.keyframes = Number(paused.keyframes);
  seen.covisibility_edges = Number(paused.covisibilityEdges);
  seen.dynamic_seen = Number(paused.dynamicSeen);
  seen.paused = Number(paused.frame);
  await sleep(2000);
  seen.paused_later = Number((await data(page)).frame);
  await page.screenshot({ path: screenshot });

  // The toggles, on the held frame: each changes what is drawn, and only its own part.
  // Frame view: pixels drawn on the marks canvas, and the label overlay's display.
  const marks = () => page.evaluate(() => {
    const canvas = document.getElementById('marks');
    const pixels = canvas.getContext('2d').getImageData(0, 0, canvas.width, canvas.height).data;
    let drawn = 0;
    for (let i = 3; i < pixels.length; i += 4) drawn += pixels[i] > 0;
    return drawn;
  });
  const display = (id) => page.evaluate((id) => getComputedStyle(document.getElementById(id)).display, id);
  const covisPixels = () => colourPixels(page, [0x3a, 0x9d, 0x54]);  // the edges' green
  seen.marks_on = await marks();
  await page.click('#show-keypoints');
  await page.click('#show-people');  // the people's ids are drawn on the same canvas
  await settle();
  seen.marks_keypoints_off = await marks();
  await page.click('#show-search');
  await settle();
  seen.marks_search_only = await marks();
  await page.click('#show-keypoints');
  await page.click('#show-search');
  await page.click('#show-people');
  await settle();
  seen.marks_back = await marks();
  seen.labels_shown = await display('labels');
  await page.click('#show-labels');
  await settle();
  seen.labels_hidden = await display('labels');
  await page.click('#show-labels');
  // The trajectory passes through every keyframe and is drawn after the edges: an edge between
  // two consecutive keyframes can lie entirely under it, so it is hidden while the edges are
  // counted (and counted itself: its orange goes and comes back).
  const orange = () => colourPixels(page, [0xe8, 0xa3, 0x3d]);
  seen.trajectory_on = await orange();
  await page.click('#show-trajectory');
  await settle();
  seen.trajectory_off = await orange();
  seen.covis_on = await covisPixels();
  await page.click('#show-covis');
  await settle();
  seen.covis_off = await covisPixels();
  await page.click('#show-covis');
  await settle();
  seen.covis_back = await covisPixels();
  await page.click('#show-trajectory');
  await settle();
  seen.trajectory_back = await orange();
  // Follow camera: off, a step leaves the orbit target where it is; on, a step moves it.
  const stepOnce = async () => {
    const before = Number((await data(page)).frame);
    await page.click('#step');
    await page.waitForFunction(`${held} && Number(document.body.dataset.frame) > ${before}`,
                               null, { timeout: 60000 });
    await settle();
  };
  const target = async () => (await data(page)).orbitTarget;
  const unfollowed = await target();
  await stepOnce();
  seen.target_kept_without_follow = (await target()) === unfollowed;
  await page.click('#follow');
  const followed = await target();
  await stepOnce();
  seen.target_moved_with_follow = (await target()) !== followed;
  seen.held_after_toggles = Number((await data(page)).frame);

  await page.click('#step');
  await page.waitForFunction(
      `${held} && Number(document.body.dataset.frame) > ${seen.held_after_toggles}`, null,
      { timeout: 60000 });
  seen.paused_step = Number((await data(page)).frame);
  await page.click('#resume');
  await page.waitForFunction(`document.body.dataset.runState === 'finished'`, null,
                             { timeout: 300000 });
  seen.finished = true;
}

// Run to the end: the maps and merges the page lists once it shows the run's last map (the
// last frame always sends the map; a merge is counted in the map it came with).
async function watchAtlas(page) {
  await page.waitForFunction(held, null, { timeout: 60000 });
  await page.click('#resume');
  const lastMapShown = `document.body.dataset.runState === 'finished' &&
                        document.body.dataset.mapShown === document.body.dataset.mapVersion`;
  await page.waitForFunction(lastMapShown, null, { timeout: 300000 });
  // The last map may be published just after the run's end is announced: a second look.
  await sleep(1000);
  await page.waitForFunction(lastMapShown, null, { timeout: 60000 });
  await settle();
  const shown = await data(page);
  seen.maps = Number(shown.maps);
  seen.merges = Number(shown.merges);
  seen.keyframes = Number(shown.keyframes);
  seen.maps_listed = await page.evaluate(
      () => [...document.querySelectorAll('#maps li')].map((item) => item.textContent));
  seen.merges_listed = await page.evaluate(
      () => [...document.querySelectorAll('#merges li')].map((item) => item.textContent));
  // Frusta in the first two maps' colours (live.js MAP_COLOURS).
  seen.map0_pixels = await colourPixels(page, [0x8a, 0xb4, 0xff]);
  seen.map1_pixels = await colourPixels(page, [0xd6, 0x7c, 0xff]);
  await page.screenshot({ path: screenshot });
  seen.finished = true;
}

// Run to the end: the people the page received, the boxes in the 3D scene and the ids written
// on the frame (the most seen at once), and whether the occupancy toggle is offered.
async function watchPeople(page) {
  await page.waitForFunction(held, null, { timeout: 60000 });
  seen.occupancy_disabled = await page.evaluate(() => document.getElementById('show-occupancy').disabled);
  seen.occupancy_tooltip = await page.evaluate(
      () => document.getElementById('occupancy-toggle').title);
  await page.click('#resume');
  await page.waitForFunction(`Number(document.body.dataset.peopleSeen) > 0 &&
                              Number(document.body.dataset.peopleLabelsSeen) > 0`,
                             null, { timeout: 300000 });
  await page.click('#pause');
  await page.waitForFunction(held, null, { timeout: 60000 });
  await settle();
  const shown = await data(page);
  seen.people_now = Number(shown.people);
  seen.people_scene = await page.evaluate(() => window.liveScene.people);
  await page.screenshot({ path: screenshot });
  await page.click('#resume');
  await page.waitForFunction(`document.body.dataset.runState === 'finished'`, null,
                             { timeout: 300000 });
  const end = await data(page);
  seen.people_seen = Number(end.peopleSeen);
  seen.people_labels_seen = Number(end.peopleLabelsSeen);
  seen.people_ids = end.peopleIds.split(' ').map(Number);
  seen.finished = true;
}

// --occupancy: the toggle is offered; switched on, the grid layer loads with known cells.
async function watchOccupancy(page) {
  await page.waitForFunction(held, null, { timeout: 60000 });
  seen.occupancy_disabled = await page.evaluate(() => document.getElementById('show-occupancy').disabled);
  await page.click('#show-occupancy');
  await page.click('#resume');
  const hasCells = `(document.body.dataset.gridCells ?? '0 0 0').split(' ').map(Number)
                        .slice(1).every((n) => n > 0)`;
  await page.waitForFunction(hasCells, null, { timeout: 300000 });
  await settle();
  const [unknown, free, occupied] = (await data(page)).gridCells.split(' ').map(Number);
  Object.assign(seen, { grid_unknown: unknown, grid_free: free, grid_occupied: occupied });
  seen.grid_meshes = await page.evaluate(() => window.liveScene?.grid ?? 0);
  await page.screenshot({ path: screenshot });
  await page.waitForFunction(`document.body.dataset.runState === 'finished'`, null,
                             { timeout: 300000 });
  seen.finished = true;
}

try {
  const page = await browser.newPage({ viewport: { width: 1400, height: 900 } });
  page.on('pageerror', (error) => { seen.page_error = String(error); });
  await page.goto(url);
  if (check === 'atlas') await watchAtlas(page);
  else if (check === 'people') await watchPeople(page);
  else if (check === 'occupancy') await watchOccupancy(page);
  else await pauseStepAndToggles(page);
} catch (error) {
  seen.error = String(error);
} finally {
  await browser.close();
}
console.log(JSON.stringify(seen));
