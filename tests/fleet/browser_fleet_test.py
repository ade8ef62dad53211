#!/usr/bin/env python3
"""The fleet page in a real headless Chromium: three real cncd on the simulated mill, each
watched by its real cncd-telemetry publishing to one real mosquitto broker, and the real
cncd-fleet reading that broker. One machine runs a program, one stays in estop, and one goes
offline when its cncd-telemetry is killed with SIGKILL (the broker's last will): the page shows
all three so, with their programs, progress, part counts and links to their own dashboards
([WEB]'s address, published in the state). A fourth "machine" published straight to the broker
with markup in its name, alarm and link shows that text as text: nothing of it runs.

Every wait is on a condition, with generous limits; nothing is judged by how long it took.
$CNCD_FLEET_SCREENSHOT, when set, names a file the page's screenshot is copied to (the docs').
"""

import argparse
import json
import os
import re
import shutil
import signal
import socket
import struct
import subprocess
import sys
import tempfile

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(HERE, "..", "web"))

from browser_fixture import Browser, require_browser  # noqa: E402
from web_fixture import Machine, Rpc, StatusWatcher, free_port, skip, wait_until  # noqa: E402

MOSQUITTO = "/usr/sbin/mosquitto"
# About a minute at F100 on the sim mill: it is still running when the page is read.
LONG_PROGRAM = "G21 G90 F20\nG1 X20\nG1 Y20\nG1 X0\nG1 Y0\nG1 X20 Y20\nM30\n"
HOSTILE = '<img src=x onerror="window.fleetXss=1">'


def parse_args():
    parser = argparse.ArgumentParser()
    for name in ("--cncd", "--cncd-telemetry", "--cncd-fleet", "--fleet-www", "--source-dir",
                 "--out-dir"):
        parser.add_argument(name, required=True)
    return parser.parse_args()


class FleetMachine(Machine):
    """A cncd on the sim mill with its cncd-telemetry publishing as mill-N to the broker; its
    [WEB] section (from Machine) is where its dashboard would be."""

    def __init__(self, args, name, broker_port):
        self.name, self.broker_port = name, broker_port
        super().__init__(args)

    def _write_ini(self):
        super()._write_ini()
        with open(self.ini, "a") as f:
            f.write(f"\n[TELEMETRY]\nMACHINE_ID = {self.name}\nMQTT_HOST = 127.0.0.1\n"
                    f"MQTT_PORT = {self.broker_port}\nMETRICS_LISTEN = off\nSHDR_PORT = 0\n"
                    "POSITION_HZ = 0\n")

    def start_telemetry(self):
        self.wait_daemon(60)  # three debug daemons start at once
        self.telemetry = self._spawn("cncd-telemetry", [self.args.cncd_telemetry, "--ini",
                                                        self.ini, "--socket", self.sock])
        self.status = StatusWatcher(self.sock)
        self.rpc = Rpc(self.sock)


def mqtt_publish(port, messages):
    """Retained QoS 0 messages, [(topic, payload)], through a minimal MQTT 3.1.1 client (no
    library needed)."""
    def string(text):
        data = text.encode()
        return struct.pack(">H", len(data)) + data

    def packet(kind, body):
        length, encoded = len(body), b""
        while True:
            byte, length = length % 128, length // 128
            encoded += bytes([byte | (128 if length else 0)])
            if not length:
                return bytes([kind]) + encoded + body
    with socket.create_connection(("127.0.0.1", port), timeout=10) as s:
        s.sendall(packet(0x10, string("MQTT") + bytes([4, 2]) + struct.pack(">H", 30) +
                         string("fleet-test")))
        assert s.recv(4)[:2] == b"\x20\x02", "no CONNACK"
        s.sendall(b"".join(packet(0x31, string(topic) + payload.encode())
                           for topic, payload in messages))
        s.sendall(b"\xe0\x00")  # DISCONNECT


def start_broker(directory):
    port = free_port()
    conf = os.path.join(directory, "mosquitto.conf")
    with open(conf, "w") as f:
        f.write(f"listener {port} 127.0.0.1\nallow_anonymous true\npersistence false\n")
    log = open(os.path.join(directory, "mosquitto.log"), "wb")
    proc = subprocess.Popen([MOSQUITTO, "-c", conf], stdout=log, stderr=subprocess.STDOUT)

    def up():
        try:
            socket.create_connection(("127.0.0.1", port), timeout=1).close()
            return True
        except OSError:
            return False
    wait_until(up, 30, "mosquitto listening")
    return proc, port


def row(browser, name):
    """The page's row of machine `name` as the page shows it, or None."""
    return browser.driver.execute_script("""
        for (const tr of document.querySelectorAll('#rows tr.machine')) {
          const title = tr.querySelector('td.name .title');
          if (!title || title.textContent !== arguments[0]) continue;
          const cell = c => tr.querySelector('td.' + c).textContent.trim();
          const a = tr.querySelector('td.name a');
          return {status: tr.dataset.status, online: cell('online'), state: cell('state'),
                  program: cell('program'), progress: cell('progress'),
                  remaining: cell('remaining'), parts: cell('parts'), alarm: cell('alarm'),
                  link: a ? a.getAttribute('href') : null,
                  markup: tr.querySelectorAll('img, script').length};
        }
        return null;""", name)


def wait_row(browser, name, predicate, what):
    return browser.wait(lambda: (lambda r: r if r and predicate(r) else None)(row(browser, name)),
                        f"{name} {what}; the page shows {row(browser, name)}")


def main():
    args = parse_args()
    require_browser()
    if not os.access(MOSQUITTO, os.X_OK):
        skip("mosquitto is not installed (scripts/setup.sh --with-broker)")
    os.makedirs(args.out_dir, exist_ok=True)
    work = tempfile.mkdtemp(prefix="cncd-fleet-test-")
    broker, broker_port = start_broker(work)
    machines, fleet, browser = [], None, None
    fleet_log = os.path.join(work, "cncd-fleet.log")
    try:
        machines = [FleetMachine(args, f"mill-{i}", broker_port) for i in (1, 2, 3)]
        for m in machines:
            m.spawn_daemon()  # all three start at once
        for m in machines:
            m.start_telemetry()
        running, estop, offline = machines
        with open(os.path.join(running.programs, "long.ngc"), "w") as f:
            f.write(LONG_PROGRAM)
        running.ready_machine()
        running.rpc.call("program.open", {"path": os.path.join(running.programs, "long.ngc")})
        running.status.wait(lambda s: s["program"]["path"].endswith("long.ngc")
                            and not s["program"]["opening"], 60, "long.ngc open")
        running.rpc.call("program.run")
        running.status.wait(lambda s: s["exec"] == "running"
                            and s["program"].get("remaining_s") is not None, 60,
                            "mill-1 running, its time left estimated")

        port = free_port()
        fleet = subprocess.Popen([args.cncd_fleet, "--broker", f"127.0.0.1:{broker_port}",
                                  "--listen", f"127.0.0.1:{port}", "--www", args.fleet_www],
                                 stdout=open(fleet_log, "wb"), stderr=subprocess.STDOUT)
        browser = Browser(1280, 720)
        browser.driver.get(f"http://127.0.0.1:{port}/")
        r1 = wait_row(browser, "mill-1", lambda r: r["status"] == "running" and r["progress"]
                      and r["remaining"], "running with its progress and time left")
        r2 = wait_row(browser, "mill-2", lambda r: r["status"] == "estop", "in estop")
        wait_row(browser, "mill-3", lambda r: r["online"] == "online", "online")
        print("mill-1:", r1, "\nmill-2:", r2, flush=True)
        assert r1["online"] == "online" and r1["state"] == "running", r1
        assert r1["program"] == "long.ngc", r1
        assert r1["progress"].endswith("%"), r1
        assert re.fullmatch(r"\d+:\d\d", r1["remaining"]), r1
        assert r1["link"] == f"http://127.0.0.1:{running.port}/", (r1, running.port)
        assert r2["online"] == "online" and r2["state"] == "estop", r2
        assert r2["link"] == f"http://127.0.0.1:{estop.port}/", r2

        offline.telemetry.send_signal(signal.SIGKILL)
        offline.telemetry.wait()
        r3 = wait_row(browser, "mill-3", lambda r: r["status"] == "offline",
                      "offline after its telemetry's SIGKILL")
        print("mill-3:", r3, flush=True)
        assert r3["online"] == "offline" and r3["state"] == "offline", r3
        # The others are as they were: the page still pushes their changes.
        wait_row(browser, "mill-1", lambda r: r["status"] == "running", "still running")
        wait_row(browser, "mill-2", lambda r: r["status"] == "estop", "still in estop")
        counts = [browser.text(f"#count-{k}") for k in ("machines", "running", "estop",
                                                          "offline")]
        assert counts == ["3", "1", "1", "1"], counts
        shot = os.path.join(args.out_dir, "fleet.png")
        browser.screenshot(shot)
        if os.environ.get("CNCD_FLEET_SCREENSHOT"):
            shutil.copy(shot, os.environ["CNCD_FLEET_SCREENSHOT"])

        mqtt_publish(broker_port, [("cncd/intruder/state", json.dumps({
            "machine": HOSTILE, "cncd": "connected", "state": "on", "exec": "idle",
            "program": {"path": "<img src=y onerror=window.fleetXss=2>"},
            "dashboard": "javascript:window.fleetXss=3",
            "last_error": {"seq": 1, "time": 1795913600,
                           "message": "<b onmouseover=x>bold</b>"}}))])


        intruder = wait_row(browser, HOSTILE, lambda r: True, "shown as text")
        print("intruder:", intruder, flush=True)
        assert intruder["markup"] == 0 and intruder["link"] is None, intruder
        assert intruder["program"] == "<img src=y onerror=window.fleetXss=2>", intruder
        assert "<b onmouseover=x>bold</b>" in intruder["alarm"], intruder
        assert browser.driver.execute_script("return window.fleetXss") is None, "markup ran"

        # A thousand more machines at once: the page takes them all and goes on.
        mqtt_publish(broker_port, [(f"cncd/load-{i:04}/state", json.dumps({
            "machine": f"load-{i:04}", "cncd": "connected", "state": "on", "exec": "running",
            "program": {"path": "/x.ngc", "progress": i / 1000}})) for i in range(1000)])
        browser.wait(lambda: browser.text("#count-machines") == "1004", "1004 machines counted")
        wait_row(browser, "load-0999", lambda r: r["status"] == "running", "running")
        wait_row(browser, "mill-1", lambda r: r["status"] == "running", "still running")
        print("fleet page: three machines shown as they are; screenshot", shot)
    finally:
        if browser is not None:
            browser.quit()
        if fleet is not None:
            fleet.send_signal(signal.SIGTERM)
            fleet.wait(timeout=20)
            if fleet.returncode != 0:
                with open(fleet_log, errors="replace") as f:
                    print(f"cncd-fleet exited {fleet.returncode}:\n{f.read()[-4000:]}",
                          file=sys.stderr)
        for m in machines:
            m.stop()
        broker.send_signal(signal.SIGTERM)
        broker.wait(timeout=20)
        shutil.rmtree(work, ignore_errors=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
