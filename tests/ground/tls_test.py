#!/usr/bin/python3
"""The ground station over TLS (--tls-cert, --tls-key) with an account of `tetra ground passwd`: a
certificate made with openssl for 127.0.0.1, the sign-in over HTTPS sets the session cookie with
`Secure` (and HttpOnly, SameSite=Strict), the session opens the API, a client offering only TLS 1.0
or 1.1 gets the server's protocol_version alert, plain HTTP on the port is not served, and a key that does not match the certificate is an input error (exit 2).
"""

import argparse
import http.client
import json
import os
import socket
import ssl
import subprocess
import sys
import tempfile
import time


def free_port():
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def make_cert(dir_, name):
    key, cert = os.path.join(dir_, name + ".key"), os.path.join(dir_, name + ".crt")
    subprocess.run(["openssl", "req", "-x509", "-newkey", "rsa:2048", "-nodes", "-keyout", key, "-out", cert,
                    "-days", "1", "-subj", "/CN=127.0.0.1", "-addext", "subjectAltName=IP:127.0.0.1"],
                   check=True, capture_output=True)
    return cert, key


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--tetra", required=True)
    ap.add_argument("--source", required=True)
    ap.add_argument("--domain", default="186")  # private to this test (tests/CMakeLists.txt)
    args = ap.parse_args()
    os.environ["CYCLONEDDS_URI"] = "file://" + os.path.join(args.source, "config", "cyclonedds-loopback.xml")
    with tempfile.TemporaryDirectory() as tmp:
        cert, key = make_cert(tmp, "ground")
        _, other_key = make_cert(tmp, "other")
        users = os.path.join(tmp, "users")
        subprocess.run([args.tetra, "ground", "passwd", "alice", "--role", "commander", "--users", users,
                        "--password-stdin"], input="tls-test-password\n", text=True, check=True,
                       capture_output=True)
        wrong = subprocess.run([args.tetra, "ground", "--listen", "127.0.0.1:0", "--users", users, "--tls-cert",
                                cert, "--tls-key", other_key, "--domain", args.domain], capture_output=True,
                               text=True, timeout=60)
        assert wrong.returncode == 2 and "--tls-key" in wrong.stderr, (wrong.returncode, wrong.stderr)

        port = free_port()
        ground = subprocess.Popen([args.tetra, "ground", "--listen", f"127.0.0.1:{port}", "--users", users,
                                   "--tls-cert", cert, "--tls-key", key, "--domain", args.domain],
                                  stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
        try:
            assert ground.stdout.readline().startswith(f"tetra ground: https://127.0.0.1:{port}/")
            context = ssl.create_default_context(cafile=cert)
            conn = http.client.HTTPSConnection("127.0.0.1", port, context=context, timeout=10)
            conn.request("POST", "/api/login", json.dumps({"user": "alice", "password": "tls-test-password"}),
                         {"Content-Type": "application/json", "Origin": f"https://127.0.0.1:{port}"})
            res = conn.getresponse()
            body = json.loads(res.read())
            cookie = res.getheader("Set-Cookie")
            assert res.status == 200, (res.status, body)
            for attribute in ("; Secure", "; HttpOnly", "; SameSite=Strict"):
                assert attribute in cookie, cookie
            conn.request("GET", "/api/session", headers={"Cookie": cookie.split(";")[0]})
            res = conn.getresponse()
            session = json.loads(res.read())
            assert res.status == 200 and session["user"] == "alice", session
            conn.close()
            # TLS 1.0 and 1.1 (a client that offers only them): the server's protocol_version alert.
            for version in (ssl.TLSVersion.TLSv1, ssl.TLSVersion.TLSv1_1):
                old = ssl.SSLContext(ssl.PROTOCOL_TLS_CLIENT)
                old.check_hostname, old.verify_mode = False, ssl.CERT_NONE
                old.set_ciphers("DEFAULT:@SECLEVEL=0")
                old.minimum_version = old.maximum_version = version
                try:
                    with socket.create_connection(("127.0.0.1", port), timeout=10) as raw:
                        with old.wrap_socket(raw):
                            refused = None
                except ssl.SSLError as e:
                    refused = str(e)
                assert refused is not None and "ALERT_PROTOCOL_VERSION" in refused, (version, refused)
            # Plain HTTP on the TLS port: no answer in HTTP.
            with socket.create_connection(("127.0.0.1", port), timeout=10) as s:
                s.sendall(f"GET /api/units HTTP/1.1\r\nHost: 127.0.0.1:{port}\r\n\r\n".encode())
                try:
                    answer = s.recv(100)
                except OSError:
                    answer = b""
                assert not answer.startswith(b"HTTP/1.1 200"), answer
            print("ground_tls: sign-in over HTTPS, cookie Secure; TLS 1.0 and 1.1 refused; a mismatched key refused (exit 2)")
            return 0
        finally:
            ground.terminate()
            ground.wait(timeout=20)


if __name__ == "__main__":
    sys.exit(main())
