#!/usr/bin/python3
"""Real-browser test of the ground station: headless Chromium driven by Selenium on the Open MCT
application served by `tetra ground` (with an accounts file made by `tetra ground passwd`), with
`tetra fusion` and `tetra sim --dds` as processes.

The operator signs in on the sign-in page, then the simulator starts: the page shows the unit
NOMINAL; the simulator's fault (gyro 2 stuck at 10 s) makes it DEGRADED with gyro 2 excluded; a
command that would leave two gyros is REFUSED and a reinstate ACCEPTED, each confirmed in the dialog,
and the event log shows both with the signed-in operator; a page of another origin (same site, so the
session cookie goes with its requests) forges commands as a text/plain form POST, a no-cors fetch and
a beacon: all refused (the ground's audit lines) and none obeyed; the two-person rule: the operator
asks for a forced exclusion (WAITING FOR APPROVAL, no Approve button for their own), signs out, a
second commander signs in, sees it and clicks Approve, and the command goes out (ACCEPTED, approved by
the second, audited as such); after `kill -9` of the ground station
and its restart, the open page recovers without a reload; after `kill -9` of the fusion service it
shows SERVICE LOST. Screenshots of each step are kept in --out. Waits are bounded (they only turn a
hang into a failure); nothing is timed.
"""

import argparse
import http.server
import json
import os
import signal
import socket
import subprocess
import sys
import threading
import time

from selenium import webdriver
from selenium.webdriver.chrome.options import Options
from selenium.webdriver.chrome.service import Service
from selenium.common.exceptions import StaleElementReferenceException
from selenium.webdriver.common.by import By
from selenium.webdriver.support import expected_conditions as ec
from selenium.webdriver.support.ui import WebDriverWait


UNIT = "ground test"  # a space: the page and the commands must carry the name as it is
UNIT_KEY = "x" + UNIT.encode().hex()  # its object key (web/tetra-model.js, unitKey)
OPERATOR = "alice"
APPROVER = "bob"  # the second commander of the two-person rule
PASSWORD = "browser-test-password"

ATTACK = """<!doctype html><html><body>
<iframe name="sink" style="display:none"></iframe>
<form id="f" method="POST" enctype="text/plain" target="sink" action="{ground}/api/command">
<input name='{{"unit":"{unit}","action":"exclude","gyro":3,"force":true,"pad":"' value='"}}'></form>
<script>
document.getElementById('f').submit();
fetch('{ground}/api/command', {{method: 'POST', mode: 'no-cors', credentials: 'include',
  headers: {{'Content-Type': 'text/plain'}},
  body: JSON.stringify({{unit: '{unit}', action: 'exclude', gyro: 4, force: true}})}});
navigator.sendBeacon('{ground}/api/command',
  new Blob([JSON.stringify({{unit: '{unit}', action: 'reset'}})], {{type: 'text/plain'}}));
document.title = 'attacked';
</script></body></html>"""


def serve_attack_page(page):
    """A page of another origin (another port of the same host: same site, so the cookie goes too)."""
    class Handler(http.server.BaseHTTPRequestHandler):
        def do_GET(self):  # noqa: N802 - the library's name
            body = page.encode()
            self.send_response(200)
            self.send_header("Content-Type", "text/html")
            self.send_header("Content-Length", str(len(body)))
            self.end_headers()
            self.wfile.write(body)

        def log_message(self, *args):
            pass

    # A thread per connection: a connection the browser opens ahead and never uses holds no other.
    server = http.server.ThreadingHTTPServer(("127.0.0.1", 0), Handler)
    server.daemon_threads = True
    threading.Thread(target=server.serve_forever, daemon=True).start()
    return server


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


def audit_lines(out):
    with open(os.path.join(out, "ground.log"), encoding="utf-8", errors="replace") as f:
        return [line for line in f if "ground audit" in line]


def sign_in(driver, wait, user):
    """On the sign-in page (already open): the user's name and password, then away from the page."""
    wait.until(ec.presence_of_element_located((By.ID, "tetra-login-form")))
    driver.find_element(By.ID, "tetra-user").send_keys(user)
    driver.find_element(By.ID, "tetra-password").send_keys(PASSWORD)
    driver.find_element(By.ID, "tetra-sign-in").click()
    wait.until(lambda d: "/login.html" not in d.current_url)


def audit_records(users):
    with open(users + ".audit.jsonl", encoding="utf-8") as f:
        return [json.loads(line) for line in f]


def command_from_page(driver, wait, button, answers=("ACCEPTED", "REFUSED", "error")):
    """Clicks a command button, confirms it in the dialog, returns the acknowledgement's text (one
    starting with one of `answers`)."""
    driver.execute_script("document.getElementById('tetra-ack').textContent = ''")

    def click(d):  # the gyro table is rebuilt when a gyro changes: find the button again then
        d.find_element(By.CSS_SELECTOR, f'button[data-command="{button}"]').click()
        return True

    wait.until(click)
    wait.until(ec.element_to_be_clickable((By.XPATH, "//button[contains(., 'Send command')]"))).click()
    wait.until(lambda d: text_of(d, "tetra-ack").startswith(answers))
    return text_of(driver, "tetra-ack")


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
    attack = None
    step = "make the operator's account"
    users = os.path.join(args.out, "users")
    for stale in (users, users + ".session-key", users + ".sessions", users + ".audit.jsonl"):
        if os.path.exists(stale):
            os.unlink(stale)
    for user in (OPERATOR, APPROVER):
        subprocess.run([args.tetra, "ground", "passwd", user, "--role", "commander", "--users", users,
                        "--password-stdin"], input=PASSWORD + "\n", text=True, check=True, capture_output=True)
    step = "start the browser"
    try:
        # The browser first: on a loaded machine it takes seconds to start, and the page must see the
        # unit NOMINAL before the fault.
        driver = start_browser()
        wait = WebDriverWait(driver, 60, poll_frequency=0.2, ignored_exceptions=[StaleElementReferenceException])

        step = "start the ground station and the service"
        data = os.path.join(args.source, "tests", "ground", "data")
        domain = ["--domain", args.domain]
        ground_argv = [args.tetra, "ground", "--listen", f"127.0.0.1:{port}", "--users", users] + domain
        ground = spawn(ground_argv, "ground.log")
        fusion = spawn([args.tetra, "fusion", "--config", os.path.join(data, "fusion.yaml")] + domain,
                       "fusion.log")
        assert http_ready(port, 30), "the ground station does not answer"

        step = "sign in"
        app = f"http://127.0.0.1:{port}/#/browse/tetra:units/tetra:unit~{UNIT_KEY}"
        driver.get(app)
        sign_in(driver, wait, OPERATOR)  # the page sent the browser to the sign-in page

        step = "page loads"
        driver.get(app)
        wait.until(ec.presence_of_element_located((By.ID, "tetra-mode")))
        wait.until(lambda d: OPERATOR in text_of(d, "tetra-operator"))
        # The service has heard no gyro yet: it says it waits (not LOST).
        wait.until(lambda d: text_of(d, "tetra-mode") == "WAITING FOR GYROS")

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

        step = "an exclude leaving two gyros is refused, a reinstate accepted, both as the operator"
        refused = command_from_page(driver, wait, "exclude gyro 1")
        assert refused.startswith("REFUSED"), refused
        accepted = command_from_page(driver, wait, "reinstate gyro 2")
        assert accepted.startswith("ACCEPTED"), accepted
        wait.until(lambda d: f"[{OPERATOR} @ ground@127.0.0.1, refused]" in text_of(d, "tetra-events")
                   and f"[{OPERATOR} @ ground@127.0.0.1, accepted]" in text_of(d, "tetra-events"))
        driver.save_screenshot(os.path.join(args.out, "3_commands.png"))
        records = audit_records(users)
        sent = [(r["unit"], r["outcome"]) for r in records if r["decision"] == "command" and r["operator"] == OPERATOR]
        assert sent[-2:] == [(UNIT, "refused"), (UNIT, "accepted")], f"commands not to '{UNIT}': {sent}"

        step = "forged cross-site requests are refused and not obeyed"
        commands_before = len([line for line in audit_lines(args.out) if f"audit: {OPERATOR} from" in line])
        refused_before = len([line for line in audit_lines(args.out) if "refused POST /api/command" in line])
        attack = serve_attack_page(ATTACK.format(ground=f"http://127.0.0.1:{port}", unit=UNIT))
        driver.get(f"http://127.0.0.1:{attack.server_port}/attack.html")
        wait.until(lambda d: d.title == "attacked")
        deadline = time.monotonic() + 30
        while time.monotonic() < deadline:  # the three requests reach the ground and are refused
            lines = audit_lines(args.out)
            if len([line for line in lines if "refused POST /api/command" in line]) >= refused_before + 3:
                break
            time.sleep(0.2)
        lines = audit_lines(args.out)
        refused_now = [line for line in lines if "refused POST /api/command" in line][refused_before:]
        assert len(refused_now) >= 3, "forged requests not all refused: " + "".join(refused_now)
        commands_after = len([line for line in lines if f"audit: {OPERATOR} from" in line])
        assert commands_after == commands_before, "a forged command was obeyed: " + "".join(lines[-5:])

        step = "a forced exclusion waits for a second commander, who approves it on the page"
        driver.get(app)
        wait.until(lambda d: text_of(d, "tetra-link") == "LIVE" and OPERATOR in text_of(d, "tetra-operator"))
        held = command_from_page(driver, wait, "exclude gyro 1 (FORCE)", ("WAITING", "ACCEPTED", "REFUSED", "error"))
        assert held.startswith("WAITING FOR APPROVAL by a second commander"), held
        asks = f"{OPERATOR} asks: exclude gyro 1 force"
        wait.until(lambda d: asks in text_of(d, "tetra-pending"))
        assert not driver.find_elements(By.CSS_SELECTOR, "button.tetra-approve"), "an Approve button for one's own"
        assert not [r for r in audit_records(users) if r["decision"] == "command" and r["command"].endswith("force")
                    and r["outcome"] in ("accepted", "refused")], "the forced exclusion went out unapproved"
        driver.save_screenshot(os.path.join(args.out, "3b_waiting_for_approval.png"))
        driver.find_element(By.ID, "tetra-sign-out").click()
        sign_in(driver, wait, APPROVER)
        driver.get(app)
        wait.until(lambda d: APPROVER in text_of(d, "tetra-operator") and asks in text_of(d, "tetra-pending"))
        driver.execute_script("document.getElementById('tetra-ack').textContent = ''")
        wait.until(ec.element_to_be_clickable((By.CSS_SELECTOR, "button.tetra-approve"))).click()
        wait.until(lambda d: f"(approved by {APPROVER})" in text_of(d, "tetra-ack"))
        approved = text_of(driver, "tetra-ack")
        assert approved.startswith("ACCEPTED"), approved
        wait.until(lambda d: asks not in text_of(d, "tetra-pending"))
        records = audit_records(users)
        approvals = [r for r in records if r["decision"] == "approval" and r["operator"] == APPROVER]
        assert approvals and approvals[-1]["unit"] == UNIT, approvals
        forced = [r for r in records if r["decision"] == "command" and r["command"].endswith("force")
                  and r["outcome"] == "accepted"]
        assert forced and forced[-1]["operator"] == OPERATOR and f"(approved by {APPROVER})" in forced[-1]["reason"], forced
        driver.save_screenshot(os.path.join(args.out, "3c_approved.png"))

        step = "the page recovers after a restart of the ground station, without a reload"
        driver.get(app)
        wait.until(lambda d: text_of(d, "tetra-link") == "LIVE")
        driver.execute_script("window.tetraNotReloaded = true")
        ground.kill()  # kill -9
        ground.wait()
        wait.until(lambda d: "GROUND LINK LOST" in text_of(d, "tetra-link"))
        ages = text_of(driver, "tetra-ages")
        wait.until(lambda d: text_of(d, "tetra-ages") != ages)  # the ages keep counting meanwhile
        driver.save_screenshot(os.path.join(args.out, "4_ground_lost.png"))
        ground = spawn(ground_argv, "ground2.log")
        wait.until(lambda d: text_of(d, "tetra-link") == "LIVE")
        assert driver.execute_script("return window.tetraNotReloaded === true"), "the page was reloaded"
        driver.save_screenshot(os.path.join(args.out, "5_recovered.png"))

        step = "SERVICE LOST after the service is killed"
        fusion.kill()
        fusion.wait()
        wait.until(lambda d: "SERVICE LOST" in text_of(d, "tetra-link"))
        driver.save_screenshot(os.path.join(args.out, "6_service_lost.png"))
        print("ground_browser: all steps passed; screenshots in", args.out)
        return 0
    except Exception as exc:  # noqa: BLE001 - report any failure with the step it happened in
        if driver is not None:
            driver.save_screenshot(os.path.join(args.out, "failed.png"))
        print(f"ground_browser: FAILED at step '{step}': {exc!r}", file=sys.stderr)
        for log in ("ground.log", "ground2.log", "fusion.log", "sim.log"):
            path = os.path.join(args.out, log)
            if os.path.exists(path):
                text = open(path, encoding="utf-8", errors="replace").read()[-1500:]
                print(f"--- {log}\n{text}", file=sys.stderr)
        return 1
    finally:
        if driver is not None:
            driver.quit()
        if attack is not None:
            attack.shutdown()
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
