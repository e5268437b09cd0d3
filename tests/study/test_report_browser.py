"""The report in a real browser: headless Chromium renders it with no errors."""

from __future__ import annotations

import shutil

import pytest
from PIL import Image

# Without these flags Chromium tries to reach Google's hosts at start-up and logs
# the refused connections; a fresh profile keeps every run alike.
CHROMIUM_FLAGS = [
    "--headless",
    "--no-sandbox",
    "--disable-gpu",
    "--disable-quic",
    "--no-first-run",
    "--disable-background-networking",
    "--disable-component-update",
    "--disable-sync",
]


@pytest.fixture(scope="module")
def chromium():
    path = shutil.which("chromium") or shutil.which("chromium-browser")
    if path is None:
        pytest.skip("Chromium is not installed (Debian: apt-get install chromium; `make test` "
                    "installs it): the report's browser test cannot run")  # fmt: skip
    return path


def test_report_renders_in_chromium(quick_study, chromium, tmp_path):
    from playwright.sync_api import sync_playwright

    out, manifest = quick_study
    errors: list[str] = []
    with sync_playwright() as pw:
        browser = pw.chromium.launch_persistent_context(
            str(tmp_path / "profile"), executable_path=chromium, args=CHROMIUM_FLAGS,
            headless=True, viewport={"width": 1280, "height": 900},
        )  # fmt: skip
        try:
            page = browser.new_page()
            page.on("console", lambda m: errors.append(m.text) if m.type == "error" else None)
            page.on("pageerror", lambda exc: errors.append(str(exc)))
            page.goto((out / "report.html").as_uri(), wait_until="load")
            images = page.evaluate(
                "Array.from(document.images).map(i => [i.alt, i.complete, i.naturalWidth])"
            )
            shot = out / "report_screenshot.png"
            page.screenshot(path=str(shot), full_page=True)
            title = page.title()
        finally:
            browser.close()
    assert errors == []
    figures = [f for part in manifest["parts"] for f in part["outputs"].get("figures", [])]
    assert len(images) == len(figures) > 30
    broken = [alt for alt, complete, width in images if not (complete and width > 0)]
    assert broken == []
    assert title == f"flexsat study — {manifest['config_name']}"
    with Image.open(shot) as im:
        assert im.width == 1280 and im.height > 10_000  # the whole page, every section
