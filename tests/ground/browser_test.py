#!/usr/bin/python3
"""Real-browser test of the ground station (issue 16): headless Chromium driven by Selenium on the
Open MCT application served by `tetra ground`, with `tetra fusion` and `tetra sim --dds` as processes.

The page loads first (on a loaded machine a browser takes seconds to start), then the simulator
starts: the page shows the unit NOMINAL; the simulator's fault (gyro 2 stuck at 10 s) makes it
DEGRADED with gyro 2 excluded; a command issued from the page (reinstate gyro 2, confirmed in the
dialog) is acknowledged; after `kill -9` of the fusion service the page shows STALE. Screenshots of
each step are kept in --out. Waits are bounded (they only turn a hang into a failure); nothing is
timed.
"""

import argparse
import os
import signal
import socket
import subprocess
import sys
import time

from selenium import webdriver
from selenium.webdriver.chrome.options import Options
from selenium.webdriver.chrome.service import Service
from selenium.webdriver.common.by import By
from selenium.webdriver.support import expected_conditions as ec
from selenium.webdriver.support.ui import WebDriverWait


UNIT = "ground-test"


def free_port():
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def http_ready(port, limit_s):
    deadline = time.monotonic() + limit_s
    while time.monotonic() < deadline:
        try:
            with socket.create_connection(("127.0.0.1", port), timeout=1):
                return True
        except OSError:
            time.sleep(0.1)
    return False


def start_browser():
    """Debian's Chromium, headless, through Debian's chromedriver."""
    options = Options()
    for flag in ("--headless=new", "--no-sandbox", "--disable-gpu", "--disable-dev-shm-usage",
                 "--window-size=1600,1000"):
        options.add_argument(flag)
    options.binary_location = "/usr/bin/chromium"
    return webdriver.Chrome(service=Service("/usr/bin/chromedriver"), options=options)


def text_of(driver, element_id):
    return driver.find_element(By.ID, element_id).text


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--tetra", required=True)
    ap.add_argument("--source", required=True)
    ap.add_argument("--out", required=True, help="screenshots and logs")
    ap.add_argument("--domain", default="183")  # private to this test (tests/CMakeLists.txt)
    args = ap.parse_args()
    os.makedirs(args.out, exist_ok=True)
    # Loopback-only discovery for every process of the test (as the C++ DDS tests do).
    os.environ["CYCLONEDDS_URI"] = "file://" + os.path.join(args.source, "config", "cyclonedds-loopback.xml")
    port = free_port()
    children = []

    def spawn(argv, log):
        child = subprocess.Popen(argv, stdout=open(os.path.join(args.out, log), "w"),
                                 stderr=subprocess.STDOUT)
        children.append(child)
        return child

    driver = None
    step = "start the browser"
    try:
        # The browser first: on a loaded machine it takes seconds to start, and the page must see the
        # unit NOMINAL before the fault.
        driver = start_browser()
        wait = WebDriverWait(driver, 60, poll_frequency=0.2)

        step = "start the ground station and the service"
        data = os.path.join(args.source, "tests", "ground", "data")
        domain = ["--domain", args.domain]
        spawn([args.tetra, "ground", "--listen", f"127.0.0.1:{port}"] + domain, "ground.log")
        fusion = spawn([args.tetra, "fusion", "--config", os.path.join(data, "fusion.yaml")] + domain,
                       "fusion.log")
        assert http_ready(port, 30), "the ground station does not answer"

        step = "page loads"
        driver.get(f"http://127.0.0.1:{port}/#/browse/tetra:units/tetra:unit~{UNIT}")
        wait.until(ec.presence_of_element_located((By.ID, "tetra-mode")))
        wait.until(lambda d: text_of(d, "tetra-mode") != "no health yet")

        step = "start the simulator"
        # 2 min of orbit at 50 Hz in real time, gyro 2 stuck from 10 s; stopped once the test is done.
        spawn([args.tetra, "sim", "orbit", "--dds", "--dds-unit", UNIT, "--unit",
               os.path.join(data, "calibration.yaml"), "--rate-hz", "50", "--minutes", "2",
               "--reference-hz", "0", "--speed", "1", "--fault", "gyro=2,kind=stuck,at=10",
               "--wait-readers", "1"] + domain, "sim.log")

        step = "unit NOMINAL"
        wait.until(lambda d: text_of(d, "tetra-mode") == "NOMINAL")
        wait.until(lambda d: text_of(d, "tetra-link") == "LIVE")
        driver.save_screenshot(os.path.join(args.out, "1_nominal.png"))

        step = "DEGRADED with gyro 2 isolated after the simulator's fault"
        wait.until(lambda d: text_of(d, "tetra-mode") == "DEGRADED")
        wait.until(lambda d: "excluded" in d.find_element(By.CSS_SELECTOR, 'tr[data-gyro="2"]').text)
        driver.save_screenshot(os.path.join(args.out, "2_degraded.png"))

        step = "a command from the page is confirmed and acknowledged"
        driver.find_element(By.CSS_SELECTOR, 'button[data-command="reinstate gyro 2"]').click()
        confirm = wait.until(ec.element_to_be_clickable(
            (By.XPATH, "//button[contains(., 'Send command')]")))
        driver.save_screenshot(os.path.join(args.out, "3_confirm.png"))
        confirm.click()
        wait.until(lambda d: text_of(d, "tetra-ack").startswith(("ACCEPTED", "REFUSED")))
        assert text_of(driver, "tetra-ack").startswith("ACCEPTED"), text_of(driver, "tetra-ack")
        driver.save_screenshot(os.path.join(args.out, "4_acknowledged.png"))

        step = "STALE after the service is killed"
        fusion.kill()
        fusion.wait()
        wait.until(lambda d: "STALE" in text_of(d, "tetra-link") or "LOST" in text_of(d, "tetra-link"))
        driver.save_screenshot(os.path.join(args.out, "5_stale.png"))
        print("ground_browser: all steps passed; screenshots in", args.out)
        return 0
    except Exception as exc:  # noqa: BLE001 - report any failure with the step it happened in
        if driver is not None:
            driver.save_screenshot(os.path.join(args.out, "failed.png"))
        print(f"ground_browser: FAILED at step '{step}': {exc!r}", file=sys.stderr)
        for log in ("ground.log", "fusion.log", "sim.log"):
            path = os.path.join(args.out, log)
            if os.path.exists(path):
                text = open(path, encoding="utf-8", errors="replace").read()[-1500:]
                print(f"--- {log}\n{text}", file=sys.stderr)
        return 1
    finally:
        if driver is not None:
            driver.quit()
        for child in children:
            if child.poll() is None:
                child.send_signal(signal.SIGTERM)
        for child in children:
            try:
                child.wait(timeout=20)
            except subprocess.TimeoutExpired:
                child.kill()
                child.wait()


if __name__ == "__main__":
    sys.exit(main())
