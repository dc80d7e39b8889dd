"""Issue 40: a hostile robot on the site. A copy of a test spec whose title, description and
licence are markup (the free-text fields: robot, joint, link and pose names are identifiers
in the schema) is published and opened in Chromium: everything shows as text, no script runs,
no dialog opens."""

from __future__ import annotations

import shutil
from pathlib import Path

import pytest

from test_site_browser import CHROMIUM, FLAGS, _need_browser, _open, _serve_folder

TITLE = '<script>alert("title")</script>'
LICENCE = "<img src=x onerror=alert(1)>"
SPECS = Path(__file__).resolve().parent / "specs"


@pytest.mark.slow
def test_a_robot_titled_script_shows_as_text(tmp_path):
    sync_api = _need_browser()
    from simkit.publish import publish
    from simkit.review.view import pose_pictures

    text = (SPECS / "planar_2r.yaml").read_text()
    assert "title: Planar 2R\n" in text and "license:" not in text
    text = text.replace(
        "title: Planar 2R\n", f"title: '{TITLE}'\ndescription: '{TITLE}'\nlicense: '{LICENCE}'\n"
    )
    spec = tmp_path / "planar_2r.yaml"
    spec.write_text(text)
    site = tmp_path / "sim"
    index = publish(site, [str(spec)], pictures=pose_pictures)
    (kit,) = index["kits"]
    for page in ("index.html", kit["page"]):
        html = (site / page).read_text()
        assert "<script>alert" not in html and "<img src=x" not in html, page
    dialogs: list[str] = []
    problems: list[str] = []
    with _serve_folder(site) as base, sync_api.sync_playwright() as pw:
        browser = pw.chromium.launch(executable_path=CHROMIUM, args=FLAGS)
        page = _open(browser, base + "index.html", problems)
        page.on("dialog", lambda d: (dialogs.append(d.message), d.dismiss()))
        assert page.locator("article.card h2").text_content() == TITLE
        assert page.locator("article.card dd", has_text=LICENCE).count() == 1
        page = _open(browser, base + kit["page"], problems)
        page.on("dialog", lambda d: (dialogs.append(d.message), d.dismiss()))
        page.evaluate("window.simkitViewer.ready")
        assert page.locator("#kit-title").text_content() == TITLE
        assert page.title().startswith(TITLE)
        assert LICENCE in page.locator("header p.facts").text_content()
        assert page.locator("#pictures figcaption").all_text_contents() == [
            "home",
            "work",
            "stretched",
        ]
        assert page.evaluate("document.querySelectorAll('script').length") == 3
        assert page.evaluate("document.querySelectorAll('img[src=x]').length") == 0
        browser.close()
    assert dialogs == [] and problems == []
    shutil.rmtree(site)
