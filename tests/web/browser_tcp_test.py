#!/usr/bin/env python3
"""The DRO of a machine with tool centre point control, in a real headless Chromium against the
real cncd on the trunnion (config/examples/sim_xyzac_trt.ini) and the real cncd-web: with the
tool tip at X40 Y0 Z20 and the table tilted to A-90 under TCP (M428), the page's tip column
shows the tip where it was while the machine column shows the joints swung round the A axis
(Y30 Z30), and the TCP label says on; after M429 it says the next move runs without it, and
after a move, off.
"""

import math
import re

from browser_fixture import Browser, require_browser
from web_fixture import Machine, parse_args

USER, PASSWORD = "tina", "tilt-the-table-5"


def number(text):
    found = re.search(r"-?\d+(?:\.\d+)?", text or "")
    return float(found.group(0)) if found else math.nan


def column(browser, kind, axes="xyz"):
    return [number(browser.text(f"#dro-{kind}-{a}")) for a in axes]


def tcp_dro(m, browser):
    browser.login(m.base, USER, PASSWORD)
    browser.wait(lambda: browser.text("#tcp-state") == "TCP off", "the TCP label, off")
    shown = browser.driver.execute_script(
        "return getComputedStyle(document.querySelector('#dro-tip-x')).display")
    assert shown != "none", shown
    for line in ("G0 X40 Y0 Z20", "M428", "G1 A-90 F1800"):
        m.rpc.call("mdi.execute", {"line": line})
    browser.wait(lambda: column(browser, "mach", "yza") == [30, 30, -90],
                 "the machine column at Y30 Z30 A-90")
    browser.wait(lambda: column(browser, "tip") == [40, 0, 20], "the tip column at X40 Y0 Z20")
    browser.wait(lambda: browser.text("#tcp-state") == "TCP on", "the TCP label, on")
    print(f"under TCP at A-90: machine {column(browser, 'mach')}, tip "
          f"{column(browser, 'tip')}, label '{browser.text('#tcp-state')}'")
    m.rpc.call("mdi.execute", {"line": "G1 A0 F1800"})
    m.rpc.call("mdi.execute", {"line": "M429"})
    browser.wait(lambda: browser.text("#tcp-state") == "TCP on (next move: off)",
                 "the TCP label after M429")
    m.rpc.call("mdi.execute", {"line": "G0 Z25"})
    browser.wait(lambda: browser.text("#tcp-state") == "TCP off", "the TCP label, off again")
    assert column(browser, "tip") == column(browser, "mach"), "A at 0: the tip is the axes"


if __name__ == "__main__":
    ARGS = parse_args()
    require_browser()
    MACHINE = Machine(ARGS, example="sim_xyzac_trt")
    try:
        MACHINE.add_user(USER, "operator", PASSWORD)
        MACHINE.start()
        MACHINE.ready_machine()
        PAGE = Browser()
        try:
            tcp_dro(MACHINE, PAGE)
        finally:
            PAGE.quit()
    finally:
        MACHINE.stop()
    print("browser TCP test: passed")
