"""The report in a real browser: headless Chromium renders it with no errors."""

from __future__ import annotations

import shutil

import numpy as np
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
            page.screenshot(path=str(shot))  # the top: title, contents, parts table
            height = page.evaluate("document.documentElement.scrollHeight")
            title = page.title()
            # Each figure as the browser painted it, cut from the page by its box.
            painted = []
            for k, figure in enumerate(page.locator("figure img").all()):
                path = out / f"figure_{k}.png"
                figure.screenshot(path=str(path), timeout=120_000)
                painted.append((figure.get_attribute("alt"), path))
            # A click enlarges a figure over the page; Escape closes it.
            page.locator("figure img").first.click()
            enlarged = page.evaluate("!document.getElementById('lightbox').hidden")
            page.keyboard.press("Escape")
            closed = page.evaluate("document.getElementById('lightbox').hidden")
        finally:
            browser.close()
    assert errors == []
    figures = [f for part in manifest["parts"] for f in part["outputs"].get("figures", [])]
    assert len(images) == len(figures) > 30
    broken = [alt for alt, complete, width in images if not (complete and width > 0)]
    assert broken == []
    assert title == f"flexsat study — {manifest['config_name']}"
    with Image.open(shot) as im:
        assert im.width == 1280 and _drawn(shot)
    assert height > 10_000  # every section, figures at full width
    assert enlarged and closed
    assert len(painted) == len(figures)
    assert [alt for alt, path in painted if not _drawn(path)] == []


def _drawn(path) -> bool:
    """Whether a painted figure shows a drawing: wide enough, and not one flat colour.

    A figure of plotted data has axes, lines and text: at least 1 % of its pixels
    differ clearly (by more than 32 of 255 grey levels) from its most common colour,
    the background. An empty canvas, a blank image or a failed decode has none.
    """
    with Image.open(path) as im:
        grey = np.asarray(im.convert("L"), dtype=float)
    if grey.shape[1] < 400:  # the layout gives every figure at least 400 px
        return False
    values, counts = np.unique(grey.round(), return_counts=True)
    background = values[np.argmax(counts)]
    return float((np.abs(grey - background) > 32.0).mean()) > 0.01


def test_the_drawn_check_refuses_an_empty_figure(tmp_path):
    blank = tmp_path / "blank.png"
    Image.new("RGB", (800, 500), "white").save(blank)
    assert not _drawn(blank)
    lines = np.full((500, 800), 255, dtype=np.uint8)
    lines[::20, :] = 0  # one dark line in 20, 5 % of the pixels
    Image.fromarray(lines).save(tmp_path / "lines.png")
    assert _drawn(tmp_path / "lines.png")
