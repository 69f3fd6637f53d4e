// The studio in a real browser: Debian's chromium, headless, driven by playwright-core.
// A new user's path: open the page, upload a photo, change a parameter and see the
// preview change, start a plot on the built-in simulator, pause, resume, finish; then
// the simulator's record must equal the one the CLI gets from the command line the page
// shows. With --screenshots DIR it writes the README's pictures.
//   node studio.test.mjs STIPPLOT PHOTO [--screenshots DIR]
import { spawn, execFileSync } from 'node:child_process';
import { mkdtempSync, copyFileSync, readFileSync, rmSync, mkdirSync, existsSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { join, basename } from 'node:path';
import { chromium } from 'playwright-core';

const [stipplot, photoPath, ...rest] = process.argv.slice(2);
const shotsAt = rest.indexOf('--screenshots');
const shots = shotsAt >= 0 ? rest[shotsAt + 1] : null;
if (!stipplot || !photoPath) {
  console.error('usage: node studio.test.mjs STIPPLOT PHOTO [--screenshots DIR]');
  process.exit(2);
}
let passed = 0, failed = 0;
function check(ok, what) {
  if (ok) { passed++; console.log('ok   ' + what); } else { failed++; console.log('FAIL ' + what); }
}
// Whatever ends this process (a failed check, an exception, the deadline), the server goes
// with it: a server left running would hold CTest's pipe open until CTest's own timeout.
let server = null;
process.on('exit', () => { if (server) server.kill('SIGKILL'); });
process.on('uncaughtException', (e) => { console.log('FAIL ' + (e.stack || e)); process.exit(1); });
process.on('unhandledRejection', (e) => { console.log('FAIL ' + (e && e.stack || e)); process.exit(1); });
const deadline = setTimeout(() => { console.error('FAIL the browser test took over 240 s'); process.exit(1); }, 240_000);

const work = mkdtempSync(join(tmpdir(), 'stipplot-studio-'));
const profile = mkdtempSync(join(tmpdir(), 'stipplot-chromium-'));
server = spawn(stipplot, ['serve', '--port', '0', '--sim-speedup', '30'], { cwd: work, stdio: ['ignore', 'pipe', 'inherit'] });
const url = await new Promise((resolve, reject) => {
  let out = '';
  server.stdout.on('data', (d) => { out += d; const m = out.match(/open (http:\/\/\S+)/); if (m) resolve(m[1]); });
  server.on('exit', (c) => reject(new Error('stipplot serve exited with ' + c)));
});
let context;
try {
  context = await chromium.launchPersistentContext(profile, {
    executablePath: '/usr/bin/chromium',
    headless: true,
    viewport: { width: 1440, height: 900 },
    args: ['--headless', '--no-sandbox', '--disable-gpu', '--disable-quic', '--no-first-run', '--disable-background-networking',
      '--disable-component-update', '--disable-sync'],
  });
  const page = context.pages()[0] || await context.newPage();
  page.on('pageerror', (e) => { failed++; console.log('FAIL page error: ' + e.message); });
  await page.goto(url);
  await page.waitForSelector('body[data-ready="1"]');
  check(await page.locator('#method option').count() >= 4, 'the page lists the drawing methods');
  check(await page.locator('#controls .ctl-wrap[data-name="-b"]').count() === 1, 'stipple\'s -b is a control, made from the CLI option');
  check((await page.locator('#controls .ctl-wrap[data-name="-b"] .def').textContent()).includes('default'), 'the control shows the CLI default');

  // Photo in: a full-size preview with its figures.
  await page.setInputFiles('#file', photoPath);
  await page.waitForFunction(() => document.body.dataset.previewGen && document.body.dataset.previewDraft === '0', null, { timeout: 60_000 });
  const first = { src: await page.getAttribute('#preview', 'src'), marks: await page.textContent('#s-marks') };
  // stipple at its defaults on this photo is one connected line in a few pieces (TSP art): its marks are those lines.
  check(Number(first.marks.replace(/,/g, '')) >= 10, `the preview counts its marks (${first.marks})`);
  check((await page.textContent('#s-time')) !== '–', 'the preview estimates the plot time');
  check(/^0\.\d+$/.test(await page.textContent('#s-fid')), 'the preview reports its fidelity');
  if (shots) { mkdirSync(shots, { recursive: true }); await page.screenshot({ path: join(shots, 'studio-preview.png') }); }

  // Drag the -b slider: reduced previews while it moves, the full one when let go.
  const slider = page.locator('#opt_b_range');
  // Which previews were shown, read from the page itself: a response body can be gone by
  // the time a listener asks for it (a newer preview replaced it).
  await page.evaluate(() => {
    window.shownDrafts = [];
    new MutationObserver(() => window.shownDrafts.push(document.body.dataset.previewDraft))
      .observe(document.body, { attributes: true, attributeFilter: ['data-preview-draft'] });
  });
  for (const v of ['18', '22', '26']) {
    const answered = page.waitForResponse((r) => r.url().endsWith('/api/preview'), { timeout: 30_000 });
    await slider.evaluate((el, val) => { el.value = val; el.dispatchEvent(new Event('input')); }, v);
    await answered;
  }
  await slider.evaluate((el) => { el.value = '30'; el.dispatchEvent(new Event('input')); el.dispatchEvent(new Event('change')); });
  await page.waitForFunction((gen) => document.body.dataset.previewDraft === '0' && document.body.dataset.previewGen !== gen,
    first.src.match(/p(\d+)\.png/)[1], { timeout: 60_000 });
  const second = { src: await page.getAttribute('#preview', 'src'), marks: await page.textContent('#s-marks') };
  const bytes = async (src) => Buffer.from(await (await fetch(new URL(src, url))).arrayBuffer());
  check(second.src !== first.src && !(await bytes(first.src)).equals(await bytes(second.src)), 'changing -b changes the preview image');
  check(second.marks !== first.marks, `and its mark count (${first.marks} -> ${second.marks})`);
  check((await page.evaluate(() => window.shownDrafts)).includes('1'), 'dragging previews the reduced photo');
  const cli = (await page.textContent('#cli')).trim();
  check(cli.includes(' -b 30'), 'the command line carries the change: ' + cli);

  // Plot on the built-in simulator: progress, pause, resume, finish.
  await page.selectOption('#port', 'sim');
  await page.click('#plot-start');
  await page.waitForFunction(() => document.body.dataset.plotStatus === 'plotting', null, { timeout: 60_000 });
  await page.waitForFunction(() => parseFloat(document.getElementById('p-pct').textContent) > 3, null, { timeout: 60_000 });
  if (shots) await page.screenshot({ path: join(shots, 'studio-plotting.png') });
  await page.click('#plot-pause');
  await page.waitForFunction(() => document.body.dataset.plotStatus === 'paused');
  await page.waitForTimeout(800);
  const held = await page.textContent('#p-lines');
  await page.waitForTimeout(1200);
  check((await page.textContent('#p-lines')) === held, `paused: no lines acknowledged while held (${held})`);
  // (The device's own state, "Hold", shows only when the streamer reports during the hold.)
  check((await page.textContent('#status-pill')) === 'paused', 'the page shows the plot paused');
  await page.click('#plot-resume');
  await page.waitForFunction(() => document.body.dataset.plotStatus === 'plotting');
  await page.waitForFunction(() => document.body.dataset.plotStatus === 'done', null, { timeout: 180_000 });
  check((await page.textContent('#p-msg')).startsWith('Plotted'), 'the page reports the finished plot: ' + await page.textContent('#p-msg'));

  // The same settings through the CLI: the simulator's record must be the same.
  const state = await (await fetch(new URL('/api/state', url))).json();
  const st = state.plots.sim;
  const cliDir = mkdtempSync(join(tmpdir(), 'stipplot-cli-'));
  copyFileSync(join(work, 'photo' + photoExt(work)), join(cliDir, 'photo' + photoExt(work)));
  const args = cli.split(/\s+/).slice(1).map((a) => a.replace(/^'|'$/g, ''));
  const out = args.indexOf('-o');
  args.splice(out, 2, '-o', 'job.gcode');
  const pv = args.indexOf('--preview');
  if (pv >= 0) args.splice(pv, 2);
  if (!args.some((a) => a.startsWith('--profile'))) args.push('--profile=' + st.profile);
  execFileSync(stipplot, args, { cwd: cliDir });
  check(readFileSync(join(cliDir, 'job.gcode')).equals(readFileSync(join(work, st.job))), 'the studio\'s job is the CLI\'s, byte for byte');
  const cliPlot = JSON.parse(execFileSync(stipplot, ['plot', 'job.gcode', '--sim', '--sim-speedup', '50', '--profile=' + st.profile,
    '--json', '--sim-out', 'cli.sim'], { cwd: cliDir, stdio: ['ignore', 'pipe', 'ignore'] }).toString().trim().split('\n').pop());
  check(cliPlot.sim_exact === true, `the CLI's plot of the same job drew exactly the job (${cliPlot.sim_segments} marks)`);
  // A pause lifts the pen and lowers it again where it was: the paper is the same, the
  // record may hold that mark twice. So the marks are compared as a set, and counted.
  const marks = (f) => readFileSync(f, 'utf8').split('\n').filter((l) => /<(circle|line|path|polyline)\b/.test(l)).map((l) => l.trim());
  const ours = marks(join(work, st.sim_svg)), theirs = marks(join(cliDir, 'cli.sim.svg'));
  const same = new Set(ours).size === new Set(theirs).size && theirs.every((m) => new Set(ours).has(m));
  check(same, `the simulator's record equals the CLI's for the same settings (${new Set(ours).size} distinct marks; ` +
    `${ours.length - new Set(ours).size} drawn twice across the pause, ${theirs.length - new Set(theirs).size} in the CLI's)`);
  if (!process.env.KEEP) rmSync(cliDir, { recursive: true, force: true }); else console.log("kept", work, cliDir);

  // A second tab sees the same state.
  const tab2 = await context.newPage();
  await tab2.goto(url);
  await tab2.waitForFunction(() => document.body.dataset.plotStatus === 'done', null, { timeout: 10_000 });
  check(await tab2.getAttribute('#preview', 'src') !== null, 'a second tab shows the same preview and the finished plot');
} catch (e) {
  failed++;
  console.log('FAIL ' + (e.stack || e));
} finally {
  if (context) await context.close();
  server.kill('SIGTERM');
  rmSync(profile, { recursive: true, force: true });
  if (!process.env.KEEP) rmSync(work, { recursive: true, force: true });
  clearTimeout(deadline);
}

function photoExt(dir) {
  for (const e of ['.png', '.jpg', '.bmp']) if (existsSync(join(dir, 'photo' + e))) return e;
  return '.png';
}
console.log(`${passed} passed, ${failed} failed`);
process.exit(failed ? 1 : 0);
