"""A real cncd on the simulated mill and a real cncd-web in front of it, for the page's tests.

Everything lives in one temporary directory: the INI copy (its [WEB] keys pointing there), the
state directory, the program directory, the users file, the socket and both daemons' logs.
"""

import argparse
import http.client
import json
import os
import re
import shutil
import signal
import socket
import subprocess
import sys
import tempfile
import threading
import time
import urllib.error
import urllib.request

SKIP = 77  # ctest's SKIP_RETURN_CODE for these tests


def skip(reason):
    print(f"SKIP: {reason}", flush=True)
    sys.exit(SKIP)


def parse_args():
    parser = argparse.ArgumentParser()
    parser.add_argument("--cncd", required=True)
    parser.add_argument("--cncd-web", required=True)
    parser.add_argument("--source-dir", required=True)
    parser.add_argument("--out-dir", required=True, help="screenshots go here (build tree)")
    return parser.parse_args()


def wait_until(condition, timeout, what, interval=0.02):
    """Polls `condition` until it returns a true value, which is returned; fails after
    `timeout` seconds naming `what`."""
    deadline = time.monotonic() + timeout
    while True:
        value = condition()
        if value:
            return value
        if time.monotonic() > deadline:
            raise AssertionError(f"timed out after {timeout} s waiting for {what}")
        time.sleep(interval)


def free_port():
    with socket.socket(socket.AF_INET, socket.SOCK_STREAM) as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def merge_patch(target, patch):
    """RFC 7386, as status.update sends its changes."""
    for key, value in patch.items():
        if value is None:
            target.pop(key, None)
        elif isinstance(value, dict) and isinstance(target.get(key), dict):
            merge_patch(target[key], value)
        else:
            target[key] = value
    return target


class RpcError(Exception):
    def __init__(self, error):
        super().__init__(f"{error.get('code')}: {error.get('message')}")
        self.code = error.get("code")
        self.message = error.get("message", "")


class Rpc:
    """A JSON-RPC client of cncd's Unix socket: one request a line, notifications skipped."""

    def __init__(self, path):
        self.sock = socket.socket(socket.AF_UNIX, socket.SOCK_STREAM)
        self.sock.connect(path)
        self.sock.settimeout(30)
        self.buffer = b""
        self.next_id = 1

    def close(self):
        self.sock.close()

    def send(self, method, params=None):
        request = {"jsonrpc": "2.0", "id": self.next_id, "method": method}
        if params is not None:
            request["params"] = params
        self.next_id += 1
        self.sock.sendall(json.dumps(request).encode() + b"\n")
        return request["id"]

    def read_message(self):
        while b"\n" not in self.buffer:
            chunk = self.sock.recv(65536)
            if not chunk:
                raise ConnectionError("cncd closed the connection")
            self.buffer += chunk
        line, self.buffer = self.buffer.split(b"\n", 1)
        return json.loads(line)

    def call(self, method, params=None):
        wanted = self.send(method, params)
        while True:
            message = self.read_message()
            if message.get("id") == wanted:
                if "error" in message:
                    raise RpcError(message["error"])
                return message["result"]


class StatusWatcher:
    """Follows cncd's whole status through status.subscribe at 10 ms on a thread of its own,
    and keeps (arrival time, daemon time, velocity, motion, x) for each update."""

    def __init__(self, path):
        self.rpc = Rpc(path)
        self.rpc.sock.settimeout(None)
        self.status = {}
        self.history = []
        self.cond = threading.Condition()
        self.rpc.send("status.subscribe", {"interval_ms": 10})
        self.thread = threading.Thread(target=self._run, daemon=True)
        self.thread.start()

    def _run(self):
        try:
            while True:
                message = self.rpc.read_message()
                if message.get("method") != "status.update":
                    continue
                params = message["params"]
                with self.cond:
                    merge_patch(self.status, params["changed"])
                    s = self.status
                    self.history.append((time.monotonic(), params.get("time", time.time()),
                                         s.get("velocity"), s.get("motion"),
                                         s.get("position", {}).get("actual", {}).get("x")))
                    self.cond.notify_all()
        except (OSError, ValueError, ConnectionError):
            pass

    def close(self):
        self.rpc.sock.shutdown(socket.SHUT_RDWR)
        self.rpc.close()

    def get(self, *keys):
        with self.cond:
            value = self.status
            for key in keys:
                value = value.get(key) if isinstance(value, dict) else None
            return json.loads(json.dumps(value))

    def wait(self, predicate, timeout, what):
        """Waits until predicate(status) holds; returns a copy of that status."""
        deadline = time.monotonic() + timeout
        with self.cond:
            while not (self.status and predicate(self.status)):
                left = deadline - time.monotonic()
                if left <= 0:
                    raise AssertionError(f"timed out after {timeout} s waiting for {what}; "
                                         f"status: {json.dumps(self.status)[:2000]}")
                self.cond.wait(left)
            return json.loads(json.dumps(self.status))


def work_xyz(status):
    p = status["work_position"]["actual"]
    return (p["x"], p["y"], p["z"])


class Machine:
    """cncd on a copy of config/examples/sim_mm.ini (or another example, `example`) and
    cncd-web in front of it."""

    def __init__(self, args, web_keys=None, example="sim_mm"):
        self.args = args
        self.web_keys = web_keys or {}
        self.example = example
        self.dir = tempfile.mkdtemp(prefix="cncd-web-test-")
        self.programs = os.path.join(self.dir, "programs")
        self.state = os.path.join(self.dir, "state")
        os.makedirs(self.programs)
        self.sock = os.path.join(self.dir, "cncd.sock")
        self.port = free_port()
        self.base = f"http://127.0.0.1:{self.port}"
        self.ini = os.path.join(self.dir, example + ".ini")
        self.users_file = os.path.join(self.dir, "web-users")
        self.procs = []
        self._write_ini()

    def _write_ini(self):
        examples = os.path.join(self.args.source_dir, "config", "examples")
        for name in os.listdir(examples):
            if name.startswith(self.example + ".") and not name.endswith(".ini"):
                shutil.copy(os.path.join(examples, name), self.dir)
        with open(os.path.join(examples, self.example + ".ini")) as f:
            text = f.read()
        text = re.sub(r"(?m)^PROGRAM_PREFIX = .*$", f"PROGRAM_PREFIX = {self.programs}", text)
        text = re.sub(r"(?m)^SOCKET = .*$", f"SOCKET = {self.sock}", text)
        text = re.sub(r"(?m)^LOG_LEVEL = .*$", "LOG_LEVEL = warn", text)
        text += ("\n[WEB]\nLISTEN = 127.0.0.1\n"
                 f"PORT = {self.port}\nPROGRAM_DIR = {self.programs}\n"
                 f"USERS_FILE = {self.users_file}\n")
        text += "".join(f"{key} = {value}\n" for key, value in self.web_keys.items())
        with open(self.ini, "w") as f:
            f.write(text)

    def _spawn(self, name, argv, **kwargs):
        log = open(os.path.join(self.dir, name + ".log"), "wb")
        proc = subprocess.Popen(argv, stdout=log, stderr=subprocess.STDOUT,
                                stdin=subprocess.DEVNULL, **kwargs)
        self.procs.append((name, proc))
        return proc

    def log(self, name):
        try:
            with open(os.path.join(self.dir, name + ".log"), errors="replace") as f:
                return f.read()[-4000:]
        except OSError:
            return ""

    def spawn_daemon(self):
        self.cncd = self._spawn("cncd", [self.args.cncd, "--ini", self.ini, "--state-dir",
                                         self.state, "--socket", self.sock])

    def wait_daemon(self, timeout=30):
        def daemon_up():
            if self.cncd.poll() is not None:
                raise AssertionError(f"cncd exited {self.cncd.returncode}:\n{self.log('cncd')}")
            try:
                Rpc(self.sock).close()
                return True
            except OSError:
                return False
        wait_until(daemon_up, timeout, "cncd's socket")

    def start(self):
        self.spawn_daemon()
        self.wait_daemon()
        web = self._spawn("cncd-web", [self.args.cncd_web, "--ini", self.ini,
                                       "--socket", self.sock])

        def web_up():
            if web.poll() is not None:
                raise AssertionError(f"cncd-web exited {web.returncode}:\n{self.log('cncd-web')}")
            try:
                with urllib.request.urlopen(self.base + "/login.html", timeout=5) as answer:
                    return answer.status == 200
            except (urllib.error.URLError, OSError):
                return False
        wait_until(web_up, 30, "cncd-web's /login.html")
        self.status = StatusWatcher(self.sock)
        self.rpc = Rpc(self.sock)

    def add_user(self, name, role, password):
        """Through the real CLI: the password on standard input."""
        done = subprocess.run([self.args.cncd_web, "--ini", self.ini, "user", "add", name,
                               "--role", role], input=(password + "\n").encode(),
                              capture_output=True, timeout=60)
        if done.returncode != 0:
            raise AssertionError(f"cncd-web user add {name} exited {done.returncode}: "
                                 f"{done.stderr.decode(errors='replace')}")

    def add_key(self, name):
        done = subprocess.run([self.args.cncd_web, "--ini", self.ini, "key", "add", name],
                              capture_output=True, timeout=60)
        if done.returncode != 0:
            raise AssertionError(f"cncd-web key add {name} exited {done.returncode}: "
                                 f"{done.stderr.decode(errors='replace')}")
        found = re.search(r"cncd_[A-Za-z0-9_-]+", done.stdout.decode())
        assert found, f"no key in the output of key add: {done.stdout!r}"
        return found.group(0)

    def ready_machine(self):
        """Out of estop, on and homed, straight through the socket (for tests about other
        things than these buttons)."""
        for method in ("machine.reset", "machine.on", "machine.home"):
            self.rpc.call(method)
        self.status.wait(lambda s: s.get("state") == "on" and all(s.get("homed", [False]))
                         and s.get("motion") == "idle", 60, "the machine on, homed, at rest")

    def stop(self):
        for attr in ("status", "rpc"):
            if hasattr(self, attr):
                try:
                    getattr(self, attr).close()
                except OSError:
                    pass
        for name, proc in reversed(self.procs):
            if proc.poll() is None:
                proc.send_signal(signal.SIGTERM)
                try:
                    proc.wait(timeout=20)
                except subprocess.TimeoutExpired:
                    proc.kill()
                    proc.wait()
            if proc.returncode not in (0, -signal.SIGTERM):
                print(f"{name} exited {proc.returncode}:\n{self.log(name)}", file=sys.stderr)
        shutil.rmtree(self.dir, ignore_errors=True)


def http_request(machine, method, path, body=None, headers=None):
    """One HTTP request to cncd-web; returns (status, headers, body) without following
    redirects."""
    conn = http.client.HTTPConnection("127.0.0.1", machine.port, timeout=30)
    try:
        conn.request(method, path, body=body, headers=headers or {})
        answer = conn.getresponse()
        return answer.status, dict(answer.getheaders()), answer.read()
    finally:
        conn.close()


def login_cookie(machine, user, password):
    status, headers, body = http_request(machine, "POST", "/api/login",
                                 json.dumps({"user": user, "password": password}),
                                 {"Content-Type": "application/json"})
    assert status == 200, f"login of {user}: {status} {body!r}"
    found = re.search(r"cncd_session=([^;]+)", headers.get("Set-Cookie", ""))
    assert found, f"no session cookie in {headers}"
    return "cncd_session=" + found.group(1)
