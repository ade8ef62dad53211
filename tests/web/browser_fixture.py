"""Debian's headless Chromium driven by python3-selenium, and what the page's tests read from it:
screenshots decoded without other libraries, the browser's process tree, logging in."""

import os
import shutil
import signal
import struct
import zlib

from web_fixture import skip, wait_until

CHROMIUM = "/usr/bin/chromium"
CHROMEDRIVER = "/usr/bin/chromedriver"
TIMEOUT = 60  # generous: two cores shared with a build, a debug cncd and the browser

try:
    from selenium import webdriver
    from selenium.common.exceptions import WebDriverException
    from selenium.webdriver.chrome.service import Service
    from selenium.webdriver.common.action_chains import ActionChains
    from selenium.webdriver.common.by import By
    from selenium.webdriver.support.ui import Select, WebDriverWait
except ImportError:  # require_browser() says so and skips
    webdriver = ActionChains = By = Select = Service = WebDriverWait = None
    WebDriverException = Exception


def require_browser():
    """Exits with SKIP, saying what is missing, when the browser cannot be driven here."""
    missing = []
    if webdriver is None:
        missing.append("python3-selenium (import selenium failed)")
    if not os.access(CHROMIUM, os.X_OK) and not shutil.which("chromium"):
        missing.append("chromium")
    if not os.access(CHROMEDRIVER, os.X_OK) and not shutil.which("chromedriver"):
        missing.append("chromedriver (package chromium-driver)")
    if missing:
        skip("cannot drive a browser: missing " + ", ".join(missing) +
             "; scripts/setup.sh --with-browser installs them")


class Browser:
    """One headless Chromium with its own profile, sized to a viewport of width x height."""

    def __init__(self, width=1920, height=1080):
        options = webdriver.ChromeOptions()
        options.binary_location = CHROMIUM if os.access(CHROMIUM, os.X_OK) else \
            shutil.which("chromium")
        for arg in ("--headless=new", "--no-sandbox", "--disable-dev-shm-usage",
                    "--disable-gpu-sandbox", "--use-angle=swiftshader",
                    "--enable-unsafe-swiftshader", "--disable-extensions",
                    "--no-first-run", "--disable-background-timer-throttling",
                    "--disable-renderer-backgrounding", f"--window-size={width},{height}"):
            options.add_argument(arg)
        driver = CHROMEDRIVER if os.access(CHROMEDRIVER, os.X_OK) else shutil.which("chromedriver")
        self.driver = webdriver.Chrome(service=Service(driver), options=options)
        self.driver.set_page_load_timeout(TIMEOUT)
        self.driver.set_script_timeout(TIMEOUT)
        self.set_viewport(width, height)

    def set_viewport(self, width, height):
        """The page's own viewport (a headless window's includes no browser chrome, but its
        inner size is not the window size)."""
        self.driver.execute_cdp_cmd("Emulation.setDeviceMetricsOverride", {
            "width": width, "height": height, "deviceScaleFactor": 1, "mobile": False})
        wait_until(lambda: self.driver.execute_script(
            "return [innerWidth, innerHeight]") == [width, height], TIMEOUT,
            f"a {width}x{height} viewport")

    def wait(self, condition, what, timeout=TIMEOUT):
        try:
            return WebDriverWait(self.driver, timeout, poll_frequency=0.05).until(
                lambda d: condition())
        except Exception as error:
            raise AssertionError(f"timed out after {timeout} s waiting for {what}: "
                                 f"{type(error).__name__} {error}") from None

    def find(self, css):
        return self.driver.find_element(By.CSS_SELECTOR, css)

    def find_all(self, css):
        return self.driver.find_elements(By.CSS_SELECTOR, css)

    def element(self, css, what=None):
        """Waits for an element present in the page."""
        return self.wait(lambda: (self.find_all(css) or [None])[0], what or css)

    def text(self, css):
        found = self.find_all(css)
        return found[0].text if found else ""

    def click(self, css):
        """Clicks an element once it is shown and enabled."""
        element = self.wait(lambda: next((e for e in self.find_all(css)
                                          if e.is_displayed() and e.is_enabled()), None),
                            f"{css} shown and enabled")
        self.driver.execute_script("arguments[0].scrollIntoView({block:'center'})", element)
        element.click()
        return element

    def tab(self, name):
        """Shows the page's panel `name` (Preview, Files, Jog / MDI ...)."""
        self.click(f'.tab[data-tab="{name}"]')
        self.wait(lambda: self.find(f'.panel[data-panel="{name}"]').is_displayed(),
                  f"the {name} panel shown")

    def login(self, base, user, password):
        self.driver.get(base + "/")
        self.wait(lambda: self.driver.current_url.endswith("/login.html"),
                  "the redirect to /login.html")
        self.element("#login-user").send_keys(user)
        self.find("#login-password").send_keys(password)
        self.find("#login-submit").click()
        self.wait(lambda: not self.driver.current_url.endswith("/login.html")
                  and self.find_all("#user") and user in self.text("#user"),
                  f"the page logged in as {user}")

    def screenshot(self, path):
        """Saves the viewport's screenshot to `path` and returns the decoded image."""
        png = self.driver.get_screenshot_as_png()
        with open(path, "wb") as f:
            f.write(png)
        return decode_png(png)

    def element_image(self, css):
        return decode_png(self.find(css).screenshot_as_png)

    def processes(self):
        """chromedriver's descendants: the browser and its helpers."""
        return descendants(self.driver.service.process.pid)

    def quit(self):
        try:
            self.driver.quit()
        except (WebDriverException, OSError):
            self.driver.service.stop()


def descendants(root):
    children = {}
    for entry in os.listdir("/proc"):
        if not entry.isdigit():
            continue
        try:
            with open(f"/proc/{entry}/stat") as f:
                stat = f.read()
        except OSError:
            continue
        ppid = int(stat[stat.rindex(")") + 2:].split()[1])
        children.setdefault(ppid, []).append(int(entry))
    found, todo = [], [root]
    while todo:
        for child in children.get(todo.pop(), []):
            found.append(child)
            todo.append(child)
    return found


def signal_all(pids, sig):
    for pid in pids:
        try:
            os.kill(pid, sig)
        except ProcessLookupError:
            pass


class Image:
    def __init__(self, width, height, channels, rows):
        self.width, self.height, self.channels, self.rows = width, height, channels, rows

    def colours(self, limit=64):
        """Distinct pixel colours (alpha left out), counting up to `limit`."""
        seen = set()
        for row in self.rows:
            for x in range(0, len(row), self.channels):
                seen.add(bytes(row[x:x + 3]))
                if len(seen) >= limit:
                    return seen
        return seen

    def blank(self):
        return len(self.colours(2)) < 2


def decode_png(data):
    """8-bit RGB or RGBA, not interlaced: what Chromium writes."""
    assert data[:8] == b"\x89PNG\r\n\x1a\n", "not a PNG"
    at, idat, header = 8, b"", None
    while at < len(data):
        length, kind = struct.unpack(">I4s", data[at:at + 8])
        body = data[at + 8:at + 8 + length]
        if kind == b"IHDR":
            header = struct.unpack(">IIBBBBB", body)
        elif kind == b"IDAT":
            idat += body
        at += 12 + length
    width, height, depth, colour, _, _, interlace = header
    assert depth == 8 and colour in (2, 6) and interlace == 0, f"unexpected PNG {header}"
    channels = 3 if colour == 2 else 4
    raw = zlib.decompress(idat)
    stride = width * channels
    rows, previous = [], bytearray(stride)
    for y in range(height):
        kind = raw[y * (stride + 1)]
        line = bytearray(raw[y * (stride + 1) + 1:(y + 1) * (stride + 1)])
        for x in range(stride):
            a = line[x - channels] if x >= channels else 0
            b = previous[x]
            c = previous[x - channels] if x >= channels else 0
            if kind == 1:
                line[x] = (line[x] + a) & 255
            elif kind == 2:
                line[x] = (line[x] + b) & 255
            elif kind == 3:
                line[x] = (line[x] + (a + b) // 2) & 255
            elif kind == 4:
                p = a + b - c
                pa, pb, pc = abs(p - a), abs(p - b), abs(p - c)
                line[x] = (line[x] + (a if pa <= pb and pa <= pc else b if pb <= pc else c)) & 255
        rows.append(line)
        previous = line
    return Image(width, height, channels, rows)


__all__ = ["ActionChains", "Browser", "By", "Select", "Image", "TIMEOUT", "decode_png", "descendants", "require_browser",
           "signal_all", "signal"]
