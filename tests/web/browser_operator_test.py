#!/usr/bin/env python3
"""The page in a real headless Chromium, against the real cncd on the simulated mill and the
real cncd-web: a setter (an operator who may also upload) logs in, resets, turns the machine
on, homes, takes the lease, uploads and opens the G81 example, sees its preview drawn, runs it
watching the DRO and progress move, ends at X4 Y5 Z3, pauses and resumes a second run, finds
both runs on the Jobs tab, jogs X
by press and hold, sees a bad MDI line's error in the log, and saves screenshots at 1024x600
and 1920x1080 into the build tree.

Every wait is on a condition (the daemon's status through its socket, or the page), with
generous time limits; nothing is judged by how long it took.
$CNCD_WEB_SCREENSHOT, when set, names a file the 1024x600 screenshot is copied to (the docs').
"""

import math
import os
import re
import shutil
import sys

from browser_fixture import ActionChains, Browser, By, Select, require_browser
from web_fixture import Machine, parse_args, wait_until, work_xyz

USER, PASSWORD = "sam", "cut-it-twice-7"
PROGRAM = "g81_example1.ngc"
G81_LINE = 7  # the G81 block's line in the example: the slow feed into the hole


def near(a, b, tolerance=1e-3):
    return abs(a - b) <= tolerance


def number(text):
    found = re.search(r"-?\d+(?:\.\d+)?", text or "")
    return float(found.group(0)) if found else math.nan


def set_range(browser, css, fraction):
    """Moves a range input to `fraction` of its span, as a drag would (input and change)."""
    element = browser.element(css)
    browser.driver.execute_script(
        "const e = arguments[0];"
        "const lo = Number(e.min || 0), hi = Number(e.max || 100);"
        "e.value = lo + (hi - lo) * arguments[1];"
        "e.dispatchEvent(new Event('input', {bubbles: true}));"
        "e.dispatchEvent(new Event('change', {bubbles: true}));", element, fraction)


def record_changes(browser):
    """From now on the page keeps every text the DRO and progress show, in order."""
    browser.driver.execute_script("""
        window.cncdSeen = [];
        const ids = ['dro-x', 'dro-y', 'dro-z', 'progress'];
        const els = ids.map(id => document.getElementById(id));
        const note = () => window.cncdSeen.push(els.map(e => e.textContent.trim())
            .concat([els[3].getAttribute('data-ratio')]));
        note();
        for (const e of els)
          new MutationObserver(note).observe(e, {subtree: true, childList: true,
                                                 characterData: true, attributes: true});
    """)


def seen(browser):
    return browser.driver.execute_script("return window.cncdSeen")


def machine_on_and_homed(m, browser):
    browser.click("#reset")
    m.status.wait(lambda s: s["state"] == "off", 30, "state off after #reset")
    browser.wait(lambda: "off" in browser.text("#state").lower(), "#state saying off")
    browser.click("#power")
    m.status.wait(lambda s: s["state"] == "on", 30, "state on after #power")
    browser.click("#lease-take")
    browser.wait(lambda: USER in browser.text("#lease-holder"), "#lease-holder naming " + USER)
    browser.click("#home-all")
    m.status.wait(lambda s: all(s["homed"]) and s["motion"] == "idle", 60, "homed after #home-all")


def upload_and_open(m, browser, source_dir, scratch):
    # Chosen from outside the program directory, as a file on the tablet would be.
    original = os.path.join(source_dir, "examples", PROGRAM)
    chosen = os.path.join(scratch, PROGRAM)
    shutil.copy(original, chosen)
    browser.tab("files")
    browser.find("#upload-input").send_keys(chosen)
    uploaded = os.path.join(m.programs, PROGRAM)
    with open(original, "rb") as f:
        expected = f.read()

    def arrived():
        try:
            with open(uploaded, "rb") as f:
                return f.read() == expected
        except OSError:
            return False
    wait_until(arrived, 60, f"{uploaded} with the example's bytes")
    row = browser.element(f'#file-list [data-file="{PROGRAM}"]', "the uploaded file's row")
    browser.driver.execute_script("arguments[0].scrollIntoView({block:'center'})", row)
    row.find_element(By.CSS_SELECTOR, ".file-open").click()
    m.status.wait(lambda s: s["program"]["path"] == uploaded and not s["program"]["opening"],
                  60, "the uploaded program open")
    browser.wait(lambda: PROGRAM in browser.text("#program-name"), "#program-name")
    browser.wait(lambda: len(browser.find_all("#program-text [data-line]")) >= 9,
                 "the program's lines in #program-text")


def preview_drawn(browser):
    browser.tab("preview")
    browser.wait(lambda: browser.text("#preview-status").lower().startswith("ready"),
                 "#preview-status ready")
    points = number(browser.text("#preview-status"))
    assert points > 0, f"preview status {browser.text('#preview-status')!r}"
    image = browser.wait(lambda: (lambda i: i if len(i.colours(3)) >= 3 else None)(
        browser.element_image("#preview")), "the preview canvas drawn (not uniform)")
    print(f"preview: {browser.text('#preview-status')!r}, canvas {image.width}x{image.height}, "
          f"{len(image.colours())}+ colours")


def first_run(m, browser):
    """Slowed by the overrides so that the page shows the run under way."""
    set_range(browser, "#override-rapid", 0.1)
    set_range(browser, "#override-feed", 0.1 / 1.5)
    m.status.wait(lambda s: s["overrides"]["rapid"] < 0.5 and s["overrides"]["feed"] < 0.5,
                  30, "the rapid and feed overrides lowered from the page")
    record_changes(browser)
    browser.click("#run")
    m.status.wait(lambda s: s["exec"] == "running", 30, "the run started by #run")
    browser.wait(lambda: browser.find_all("#program-text [data-line].current"),
                 "the running line highlighted")
    done = m.status.wait(lambda s: s["exec"] == "idle" and s["program"]["result"] != "", 120,
                         "the run's end")
    assert done["program"]["result"] == "done", done["program"]
    assert all(near(a, b) for a, b in zip(work_xyz(done), (4, 5, 3))), work_xyz(done)
    browser.wait(lambda: [number(browser.text(f"#dro-{a}")) for a in "xyz"] == [4, 5, 3],
                 "the DRO at X4 Y5 Z3")
    # The mill has no TCP: no tool tip column and no TCP state.
    assert done.get("tool_tip") is None and done.get("tcp") is None, done.get("tcp")
    shown = browser.driver.execute_script(
        "return [getComputedStyle(document.querySelector('#dro-tip-x')).display,"
        " document.querySelector('#tcp-state').hidden]")
    assert shown == ["none", True], shown
    texts = seen(browser)
    zs = {number(t[2]) for t in texts}
    ratios = {float(t[4]) for t in texts if t[4] not in (None, "")}
    print(f"run 1: {len(texts)} DRO/progress changes shown, Z values {sorted(zs)[:12]}..., "
          f"progress ratios {sorted(ratios)}")
    assert any(1.5 < z < 2.8 for z in zs), f"no Z shown while drilling: {sorted(zs)}"
    assert len({tuple(t[:3]) for t in texts}) >= 4, "the DRO barely changed during the run"
    assert any(0 < r < 1 for r in ratios), f"no progress shown during the run: {ratios}"
    browser.wait(lambda: near(float(browser.find("#progress").get_attribute("data-ratio")), 1),
                 "#progress at 1 after the run")


def paused_run(m, browser):
    browser.click("#run")
    # Past R (Z2.8) the drill feeds at 10 %: seconds for the click to land in the hole.
    m.status.wait(lambda s: s["exec"] == "running" and s["program"]["line"] == G81_LINE and
                  s["motion"] == "moving" and work_xyz(s)[2] < 2.7, 60,
                  "the second run feeding into the hole")
    browser.click("#pause")
    paused = m.status.wait(lambda s: s["exec"] == "paused" and s["velocity"] == 0, 30,
                           "the run paused by #pause")
    z = work_xyz(paused)[2]
    assert 1.5 < z < 2.8, f"paused at Z {z}, not in the hole"
    browser.wait(lambda: near(number(browser.text("#dro-z")), z, 2e-3), "#dro-z at the pause")
    browser.click("#resume")
    m.status.wait(lambda s: s["exec"] == "running", 30, "the run resumed by #resume")
    done = m.status.wait(lambda s: s["exec"] == "idle", 120, "the resumed run's end")
    assert done["program"]["result"] == "done", done["program"]
    assert all(near(a, b) for a, b in zip(work_xyz(done), (4, 5, 3))), work_xyz(done)
    print(f"run 2: paused at Z {z:.4f}, resumed, ended at {work_xyz(done)}")


def job_history(m, browser):
    """The Jobs tab lists both runs, newest first, as the daemon's job history has them."""
    history = m.rpc.call("jobs.history", {"limit": 10})["jobs"]
    assert [j["result"] for j in history[:2]] == ["done", "done"], history
    browser.tab("jobs")
    browser.wait(lambda: len(browser.find_all("#job-rows tr.job-done")) >= 2,
                 "both runs listed as done on the Jobs tab")
    rows = browser.find_all("#job-rows tr")
    assert rows[0].get_attribute("data-job") == str(history[0]["id"]), "the newest run first"
    assert PROGRAM in rows[0].text and USER in rows[0].text, rows[0].text
    browser.wait(lambda: re.search(r"\b2 done\b", browser.text("#jobs-stats")),
                 "the sums say two runs done")
    print(f"jobs tab: {len(rows)} runs listed, {browser.text('#jobs-stats')}")


def jog_hold(m, browser):
    set_range(browser, "#override-feed", 1 / 1.5)
    set_range(browser, "#override-rapid", 1.0)
    browser.tab("manual")
    Select(browser.element("#jog-mode")).select_by_value("continuous")
    speed = browser.find("#jog-speed")
    speed.clear()
    speed.send_keys("300")  # units/min: 5 mm/s
    button = browser.element("#jog-x-plus")
    browser.driver.execute_script("arguments[0].scrollIntoView({block:'center'})", button)
    ActionChains(browser.driver).move_to_element(button).click_and_hold().perform()
    start = m.status.wait(lambda s: s["motion"] == "jogging" and s["velocity"] > 0, 30,
                          "X jogging while #jog-x-plus is held")
    x0 = start["position"]["actual"]["x"]
    # Held well past several heartbeat periods: the page's heartbeats keep it going.
    moving = m.status.wait(lambda s: s["position"]["actual"]["x"] > x0 + 3, 30,
                           "X 3 mm further while held")
    assert near(moving["velocity"], 5, 0.5), f"jog speed {moving['velocity']} mm/s, not 5"
    ActionChains(browser.driver).release().perform()
    stopped = m.status.wait(lambda s: s["motion"] == "idle" and s["velocity"] == 0, 30,
                            "the jog stopped on release")
    # The commanded position: the simulated drive's actual one may still be a servo period
    # behind when the status that says idle is read.
    x_stop = stopped["position"]["commanded"]["x"]
    count = len(m.status.history)
    wait_until(lambda: len(m.status.history) > count + 20, 30, "20 more status updates")
    assert near(m.status.get("position", "commanded", "x"), x_stop, 1e-9), "X moved after rest"
    browser.wait(lambda: near(number(browser.text("#dro-x")), work_xyz(stopped)[0], 2e-3),
                 "#dro-x at the jog's end")
    print(f"jog: held from X {x0:.3f}, released at rest at X {x_stop:.3f}")


def bad_mdi(browser):
    before = len(browser.find_all("#log .log-entry"))
    field = browser.element("#mdi-input")
    field.clear()
    field.send_keys("G1 X5 F100 G0")  # two motion codes in one block
    browser.click("#mdi-send")
    # The interpreter's own words ("Two g codes used from same modal group").
    entry = browser.wait(lambda: next((e for e in browser.find_all("#log .log-entry")[before:]
                                       if "modal group" in e.text.lower()), None),
                         "the bad MDI line's error in #log")
    assert "log-error" in entry.get_attribute("class").split(), entry.get_attribute("class")
    print(f"MDI error shown: {entry.text!r}")


def screenshots(browser, out_dir):
    browser.tab("preview")
    for width, height in ((1024, 600), (1920, 1080)):
        browser.set_viewport(width, height)
        browser.driver.execute_async_script(
            "requestAnimationFrame(() => requestAnimationFrame(arguments[0]))")
        path = os.path.join(out_dir, f"web-operator-{width}x{height}.png")
        image = browser.screenshot(path)
        assert (image.width, image.height) == (width, height), (image.width, image.height)
        colours = len(image.colours())
        assert colours >= 16, f"{path} is (nearly) blank: {colours} colours"
        for css in ("#estop", "#state", "#dro-x"):
            box = browser.driver.execute_script(
                "const r = document.querySelector(arguments[0]).getBoundingClientRect();"
                "return [r.left, r.top, r.right, r.bottom, r.width * r.height];", css)
            assert box[4] > 0 and box[0] >= 0 and box[1] >= 0 and box[2] <= width + 1 and \
                box[3] <= height + 1, f"{css} not fully on screen at {width}x{height}: {box}"
        print(f"screenshot {path}: {colours}+ colours")
    # The Jobs tab at the tablet's size: its table fits the width.
    browser.set_viewport(1024, 600)
    browser.tab("jobs")
    path = os.path.join(out_dir, "web-jobs-1024x600.png")
    browser.screenshot(path)
    overflow = browser.driver.execute_script(
        "const t = document.getElementById('job-table');"
        "return t.getBoundingClientRect().right - window.innerWidth;")
    assert overflow <= 1, f"the job table runs {overflow} px past the screen's right"
    print(f"screenshot {path}")
    browser.tab("preview")


def docs_screenshot(browser, out_dir):
    """With $CNCD_WEB_SCREENSHOT: the page at 1024x600 with the program open and its preview
    in colour, for docs/web.md."""
    docs = os.environ.get("CNCD_WEB_SCREENSHOT")
    if not docs:
        return
    browser.set_viewport(1024, 600)
    browser.driver.execute_async_script(
        "requestAnimationFrame(() => requestAnimationFrame(arguments[0]))")
    path = os.path.join(out_dir, "web-dashboard.png")
    assert not browser.screenshot(path).blank(), path
    shutil.copy(path, docs)
    browser.set_viewport(1920, 1080)


def main():
    args = parse_args()
    require_browser()
    os.makedirs(args.out_dir, exist_ok=True)
    # Held buttons here are about the page, not about lost heartbeats (browser_access_test):
    # a long heartbeat keeps a browser slowed by a busy machine from losing its jog.
    m = Machine(args, {"JOG_HEARTBEAT": 1})
    browser = None
    try:
        m.add_user(USER, "setter", PASSWORD)
        m.start()
        browser = Browser(1920, 1080)
        browser.login(m.base, USER, PASSWORD)
        machine_on_and_homed(m, browser)
        upload_and_open(m, browser, args.source_dir, m.dir)
        preview_drawn(browser)
        docs_screenshot(browser, args.out_dir)
        first_run(m, browser)
        paused_run(m, browser)
        job_history(m, browser)
        jog_hold(m, browser)
        bad_mdi(browser)
        screenshots(browser, args.out_dir)
    finally:
        if browser is not None:
            browser.quit()
        m.stop()
    print("browser operator test: passed")
    return 0


if __name__ == "__main__":
    sys.exit(main())
