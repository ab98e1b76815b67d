#!/usr/bin/env python3
"""Real-browser test of the ground station (issue 16): headless Chromium driven by Selenium on the
Open MCT application served by `tetra demo --web`.

The page loads and shows the unit NOMINAL; the simulator's fault (gyro 2 stuck) makes it DEGRADED
with gyro 2 excluded; a command issued from the page (reinstate gyro 2, confirmed in the dialog) is
acknowledged; after `kill -9` of the fusion service the page shows STALE. Screenshots of each step
are kept in --out. Waits are bounded (they only turn a hang into a failure); nothing is timed.
"""

import argparse
import os
import re
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


def free_port():
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def wait_for_line(path, pattern, limit_s):
    deadline = time.monotonic() + limit_s
    while time.monotonic() < deadline:
        if os.path.exists(path):
            m = re.search(pattern, open(path, encoding="utf-8", errors="replace").read())
            if m:
                return m
        time.sleep(0.1)
    return None


def http_ready(port, limit_s):
    deadline = time.monotonic() + limit_s
    while time.monotonic() < deadline:
        try:
            with socket.create_connection(("127.0.0.1", port), timeout=1):
                return True
        except OSError:
            time.sleep(0.1)
    return False


def text_of(driver, element_id):
    return driver.find_element(By.ID, element_id).text


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--tetra", required=True)
    ap.add_argument("--source", required=True)
    ap.add_argument("--out", required=True, help="screenshots and logs")
    ap.add_argument("--domain", default="183")
    args = ap.parse_args()
    os.makedirs(args.out, exist_ok=True)
    port = free_port()
    demo_log = os.path.join(args.out, "demo.log")
    keep = os.path.join(args.out, "demo")
    # 60 s of orbit in real time, gyro 2 stuck from 8 s; the test ends it once it has what it needs.
    demo = subprocess.Popen(
        [args.tetra, "demo", "--web", "--listen", f"127.0.0.1:{port}", "--domain", args.domain,
         "--seconds", "60", "--speed", "1", "--fault", "gyro=2,kind=stuck,at=8", "--keep", keep],
        stdout=open(demo_log, "w"), stderr=subprocess.STDOUT)
    driver = None
    step = "start"
    try:
        pid_match = wait_for_line(demo_log, r"service pid (\d+)", 30)
        assert pid_match, "the demo did not start its service"
        service_pid = int(pid_match.group(1))
        assert http_ready(port, 30), "the ground station does not answer"

        options = Options()
        for flag in ("--headless=new", "--no-sandbox", "--disable-gpu", "--disable-dev-shm-usage",
                     "--window-size=1600,1000"):
            options.add_argument(flag)
        options.binary_location = "/usr/bin/chromium"
        driver = webdriver.Chrome(service=Service("/usr/bin/chromedriver"), options=options)
        wait = WebDriverWait(driver, 60, poll_frequency=0.2)

        step = "page loads, unit NOMINAL"
        driver.get(f"http://127.0.0.1:{port}/#/browse/tetra:units/tetra:unit~tetra-1")
        wait.until(ec.presence_of_element_located((By.ID, "tetra-mode")))
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
        os.kill(service_pid, signal.SIGKILL)
        wait.until(lambda d: "STALE" in text_of(d, "tetra-link") or "LOST" in text_of(d, "tetra-link"))
        driver.save_screenshot(os.path.join(args.out, "5_stale.png"))
        print("ground_browser: all steps passed; screenshots in", args.out)
        return 0
    except Exception as exc:  # noqa: BLE001 - report any failure with the step it happened in
        if driver is not None:
            driver.save_screenshot(os.path.join(args.out, "failed.png"))
        print(f"ground_browser: FAILED at step '{step}': {exc!r}", file=sys.stderr)
        if os.path.exists(demo_log):
            print(open(demo_log, encoding="utf-8", errors="replace").read()[-3000:], file=sys.stderr)
        return 1
    finally:
        if driver is not None:
            driver.quit()
        demo.send_signal(signal.SIGTERM)
        try:
            demo.wait(timeout=20)
        except subprocess.TimeoutExpired:
            demo.kill()
            demo.wait()


if __name__ == "__main__":
    sys.exit(main())
