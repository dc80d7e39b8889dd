"""The site's HTML (simkit/publish/pages.py, markdown.py): escaped, from the kit's own data."""

from __future__ import annotations

from simkit.publish import markdown, pages

HOSTILE = '<script>alert("x")</script> & <img src=x onerror=alert(1)>'


def _kit(title: str) -> dict:
    files = [
        {"path": "k_description/robot.json", "size": 10, "sha256": "ab", "url": "k/robot.json"}
    ]
    return {
        "name": "k",
        "title": title,
        "folder": "k/",
        "top_folder": "k_description/",
        "zip": {"path": "k-sim-kit.zip", "size": 2_500_000, "sha256": "cd"},
        "files": files,
        "licence": HOSTILE,
        "category": "arm",
        "dof": 1,
        "mass": 1.5,
        "reach": None,
        "thumbnail": None,
        "checks": {"urdf": {"passed": 3, "total": 3, "tools": ["yourdfpy"]}},
    }


def test_every_string_from_the_robot_is_escaped_on_both_pages():
    doc = {
        "description": HOSTILE,
        "joints": [{"name": HOSTILE, "type": "revolute", "parent": "a", "child": "b"}],
        "frames": {HOSTILE: {"role": HOSTILE}},
        "published": {HOSTILE: 1.0},
    }
    readme = f"## Quickstart\n\n{HOSTILE}\n\n```python\nprint('{HOSTILE}')\n```\n"
    for html in (
        pages.gallery({"kits": [_kit(HOSTILE)]}),
        pages.kit_page(_kit(HOSTILE), doc, readme, {}),
    ):
        assert "<script>alert" not in html and "<img src=x" not in html
        assert "&lt;script&gt;alert(&quot;x&quot;)&lt;/script&gt;" in html
    page = pages.kit_page(_kit(HOSTILE), doc, readme, {})
    assert "2.5 MB" in page and "3 of 3 checks passed" in page and "yourdfpy" in page


def test_json_for_the_viewer_cannot_close_its_script_element():
    text = pages.script_json({"files": ["</script><script>alert(1)</script>"]})
    assert "<" not in text and ">" not in text
    assert "\\u003c/script\\u003e" in text


def test_readme_sections_become_html_with_code_kept_verbatim():
    readme = "# T\n\n## Quickstart\n\nRun `x`:\n\n```sh\na < b && c\n```\n\n## Next\n\nno"
    html = markdown.to_html(markdown.section(readme, "Quickstart"))
    code = '<pre><code class="language-sh">a &lt; b &amp;&amp; c</code></pre>'
    assert html == "<p>Run <code>x</code>:</p>\n" + code
    assert markdown.section(readme, "Missing") == ""
    assert markdown.to_html("- a\n  b\n- c") == "<ul><li>a b</li><li>c</li></ul>"
