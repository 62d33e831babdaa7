"""Opening a report in a real browser: headless Chromium (Debian's chromium + chromium-driver) through selenium.

What a page is checked for: it renders (the page's script sets ``data-rendered``) with no console errors and no
network request but the file itself, and every plot's traces as plotly holds them (row, samples before
decimation, points drawn), the failsafe marker lines, the armed shading, the log's own warning markers, flight
modes, failsafe entries and events, and each input's header table, read back from the live page. A screenshot of every
page is kept under ``build/test-artifacts/`` (or ``$BATTGEN_ARTIFACTS``) for a person to look at.
"""

from __future__ import annotations

import json
import os
import shutil
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import pytest

CHROMIUM = "/usr/bin/chromium"
CHROMEDRIVER = "/usr/bin/chromedriver"
ROOT = Path(__file__).resolve().parents[2]
ARTIFACTS = Path(os.environ.get("BATTGEN_ARTIFACTS", ROOT / "build" / "test-artifacts"))
# flags for a closed network and a root user (the machine's own notes on running Chromium here)
FLAGS = (
    "--headless=new",
    "--no-sandbox",
    "--disable-gpu",
    "--disable-quic",
    "--no-first-run",
    "--disable-background-networking",
    "--disable-component-update",
    "--disable-sync",
    "--window-size=1400,1800",
)
_READ_PLOTS = """
return Array.from(document.querySelectorAll('.battery-plot, #trends')).map(function (div) {
  return {
    id: div.id,
    traces: (div.data || []).map(function (t) {
      return {name: t.name, row: t.meta ? (t.meta.row || t.meta.quantity) : null,
              samples: t.meta && t.meta.samples !== undefined ? t.meta.samples : null,
              points: t.x.length};
    }),
    markers: ((div.layout && div.layout.shapes) || []).filter(function (s) {
      return s.name && s.name.indexOf('failsafe') === 0;
    }).map(function (s) { return {t: s.x0, level: s.name.slice(9)}; }),
    armed: ((div.layout && div.layout.shapes) || []).filter(function (s) {
      return s.name === 'armed';
    }).map(function (s) { return [s.x0, s.x1]; }),
    warnings: ((div.layout && div.layout.shapes) || []).filter(function (s) {
      return s.name && s.name.indexOf('log warning ') === 0;
    }).map(function (s) { return {t: s.x0, level: s.name.slice(12)}; }),
    modes: ((div.layout && div.layout.shapes) || []).filter(function (s) {
      return s.name && s.name.indexOf('mode ') === 0;
    }).map(function (s) { return {t: s.x0, mode: s.name.slice(5)}; }),
    failsafes: ((div.layout && div.layout.shapes) || []).filter(function (s) {
      return s.name && s.name.indexOf('log failsafe ') === 0;
    }).map(function (s) { return {t: s.x0, what: s.name.slice(13)}; }),
    events: ((div.layout && div.layout.shapes) || []).filter(function (s) {
      return s.name && s.name.indexOf('log event ') === 0;
    }).map(function (s) { return {t: s.x0, what: s.name.slice(10)}; })
  };
});
"""
_READ_HEADERS = """
return Array.from(document.querySelectorAll('table.log-header')).map(function (table) {
  var rows = {};
  table.querySelectorAll('tr').forEach(function (tr) {
    rows[tr.querySelector('th').textContent] = tr.querySelector('td').textContent;
  });
  return rows;
});
"""


@dataclass
class Page:
    plots: list[dict[str, Any]]
    headers: list[dict[str, str]]  # each input's header table as the page shows it: label -> text
    console: list[dict[str, Any]]
    requests: set[str]
    load_s: float
    screenshot: Path


def browser_available() -> bool:
    return Path(CHROMIUM).exists() and Path(CHROMEDRIVER).exists() and shutil.which("chromium") is not None


def require_browser() -> None:
    """Skip without Chromium on a developer machine; in CI (.ci/run installs it) its absence is a failure."""
    if browser_available():
        return
    if os.environ.get("CI"):
        pytest.fail("Chromium and ChromeDriver are missing: .ci/run installs Debian's chromium and chromium-driver")
    pytest.skip("headless Chromium not installed (apt-get install chromium chromium-driver)")


def open_page(path: Path, name: str) -> Page:
    webdriver = pytest.importorskip("selenium.webdriver")
    from selenium.webdriver.chrome.options import Options
    from selenium.webdriver.chrome.service import Service

    options = Options()
    options.binary_location = CHROMIUM
    for flag in FLAGS:
        options.add_argument(flag)
    options.set_capability("goog:loggingPrefs", {"browser": "ALL", "performance": "ALL"})
    driver = webdriver.Chrome(service=Service(CHROMEDRIVER), options=options)
    try:
        start = time.perf_counter()
        driver.get(path.resolve().as_uri())
        deadline = start + 60
        while driver.execute_script("return document.body.getAttribute('data-rendered')") != "true":
            assert time.perf_counter() < deadline, f"{path}: the plots did not render within 60 s"
            time.sleep(0.05)
        load_s = time.perf_counter() - start
        plots = driver.execute_script(_READ_PLOTS)
        headers = driver.execute_script(_READ_HEADERS)
        console = driver.get_log("browser")
        requests = set()
        for entry in driver.get_log("performance"):
            message = json.loads(entry["message"])["message"]
            if message["method"] == "Network.requestWillBeSent":
                requests.add(message["params"]["request"]["url"])
        ARTIFACTS.mkdir(parents=True, exist_ok=True)
        shot = ARTIFACTS / f"{name}.png"
        driver.save_screenshot(str(shot))
        return Page(plots, headers, console, requests, load_s, shot)
    finally:
        driver.quit()
