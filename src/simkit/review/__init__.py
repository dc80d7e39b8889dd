"""Pictures of a kit for people: MuJoCo renders (`render`), a self-contained HTML visual diff
for pull requests (`diff_html`) and a three.js viewer served on 127.0.0.1 (`view`).

Reads built kits only (folders or zips), so it sits beside `diff` and `publish`.
"""
