"""Headless Chromium for the report tests: load a page offline, run a probe, return the DOM.

The probe is a test-only script put in front of a copy of the page (its hash added to the page's
Content-Security-Policy, which otherwise runs no script but the page's own). When the page has
loaded it records in attributes of <html>: every error and CSP violation seen, and each image's
natural size; ``actions`` (JavaScript) can click and type first and record what happened.
"""
from __future__ import annotations

import base64
import hashlib
import os
import re
import shutil
import subprocess
from pathlib import Path

import pytest

FLAGS = ["--headless", "--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run",
         "--disable-background-networking", "--disable-component-update", "--disable-sync",
         "--disable-default-apps", "--disable-extensions", "--hide-scrollbars", "--mute-audio"]

PROBE = """(function () {
  var errors = [], root = document.documentElement;
  function note(text) {  // kept current, so that a late report still reaches the dumped DOM
    errors.push(text);
    root.setAttribute("data-probe-errors", JSON.stringify(errors));
  }
  root.setAttribute("data-probe-errors", "[]");
  window.addEventListener("error", function (e) {
    note("error: " + (e.message || (e.target && e.target.tagName) || "?"));
  }, true);
  document.addEventListener("securitypolicyviolation", function (e) {
    note("csp: " + e.violatedDirective + " " + e.blockedURI);
  });
  window.addEventListener("load", function () {
    Array.prototype.forEach.call(document.images, function (img) {
      img.setAttribute("data-natural", img.naturalWidth + "x" + img.naturalHeight + (img.complete ? "" : " incomplete"));
    });
    try { ACTIONS } catch (e) { note("probe: " + e); }
    root.setAttribute("data-probe-loaded", "1");
  });
})();"""


def in_ci() -> bool:
    return os.environ.get("CI", "").strip().lower() in ("true", "1", "yes")


def chromium() -> str:
    """The browser, or skip (outside CI only: CI installs it, so there its absence is a failure)."""
    for name in ("chromium", "chromium-browser"):
        path = shutil.which(name)
        if path:
            return path
    if in_ci():
        pytest.fail("CI is set but chromium is missing: .ci/run installs Debian's chromium before the tests")
    pytest.skip("chromium is not installed (Debian: apt-get install chromium); the browser tests run in CI")


def _with_probe(html: str, actions: str) -> str:
    import html as htmllib

    probe = PROBE.replace("ACTIONS", actions)
    digest = "'sha256-" + base64.b64encode(hashlib.sha256(probe.encode()).digest()).decode() + "'"

    def allow(m):
        directives = []
        for d in htmllib.unescape(m.group(2)).split(";"):
            words = d.split()
            if words and words[0] == "script-src":
                d = " ".join(["script-src"] + [w for w in words[1:] if w != "'none'"] + [digest])
            directives.append(d.strip())
        return m.group(1) + htmllib.escape("; ".join(directives), quote=True) + m.group(3)

    pattern = r'(<meta http-equiv="Content-Security-Policy" content=")([^"]*)(">)'
    html, n = re.subn(pattern, allow, html, count=1)
    assert n == 1 and "sha256-" in html, "the page has no Content-Security-Policy to extend"
    at = re.search(pattern, html).end()  # right after the policy, before anything it governs
    return html[:at] + f"\n<script>{probe}</script>" + html[at:]


def run(args: list[str], tmp: Path) -> subprocess.CompletedProcess:
    profile = tmp / "chromium-profile"
    cmd = [chromium(), *FLAGS, f"--user-data-dir={profile}", "--enable-logging=stderr", "--v=0", *args]
    return subprocess.run(cmd, capture_output=True, text=True, timeout=180)


def console_lines(stderr: str) -> list[str]:
    """What the page wrote to its console (Chromium logs it as 'CONSOLE' lines)."""
    return [line for line in stderr.splitlines() if ":CONSOLE" in line]


def load(page: Path, tmp: Path, actions: str = "") -> tuple[str, list[str]]:
    """(DOM after load and the probe, console lines) of ``page``, from a probed copy."""
    copy = tmp / f"probed-{page.name}"
    copy.write_text(_with_probe(page.read_text(encoding="utf-8"), actions), encoding="utf-8")
    done = run(["--virtual-time-budget=5000", "--dump-dom", copy.resolve().as_uri()], tmp)
    assert done.returncode == 0, done.stderr[-2000:]
    return done.stdout, console_lines(done.stderr)


def screenshot(page: Path, png: Path, tmp: Path, size=(1200, 1800)) -> list[str]:
    """Render the page itself (unprobed) to ``png``; returns its console lines."""
    done = run([f"--window-size={size[0]},{size[1]}", f"--screenshot={png}", page.resolve().as_uri()], tmp)
    assert done.returncode == 0, done.stderr[-2000:]
    return console_lines(done.stderr)
