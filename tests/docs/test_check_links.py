#!/usr/bin/python3
"""scripts/docs/check_links.py on a small site written here: it must name every broken link
(a missing page, a missing anchor, a path out of the site) and every resource loaded from the
network, and pass the same site once they are fixed.

    test_check_links.py scripts/docs/check_links.py
"""
import os
import subprocess
import sys
import tempfile


def write(path, text):
    os.makedirs(os.path.dirname(path), exist_ok=True)
    with open(path, "w", encoding="utf-8") as f:
        f.write(text)


def run(checker, site):
    r = subprocess.run([sys.executable, checker, site], capture_output=True, text=True)
    return r.returncode, r.stdout + r.stderr


def main():
    checker = sys.argv[1]
    failures = []

    def expect(condition, what):
        if not condition:
            failures.append(what)

    with tempfile.TemporaryDirectory() as site:
        write(os.path.join(site, "_static", "style.css"), "body {}")
        write(os.path.join(site, "_static", "mathjax", "MathJax.js"), "")
        write(os.path.join(site, "reference", "schemes.html"),
              '<h1 id="schemes">Schemes</h1><p id="scheme-se1">se1</p><a name="old-anchor"></a>'
              '<a href="../index.html#top">home</a>')
        good_index = ('<html><head><link rel="stylesheet" href="_static/style.css">'
                      '<script src="_static/mathjax/MathJax.js?config=TeX-AMS_CHTML"></script></head>'
                      '<body id="top"><a href="reference/schemes.html#scheme-se1">se1</a>'
                      '<a href="reference/schemes.html#old-anchor">old</a>'
                      '<a href="#top">top</a><a href="reference/">dir</a>'
                      '<a href="https://example.org/paper">an external link, not fetched</a>'
                      '<a href="mailto:someone@example.org">mail</a></body></html>')
        write(os.path.join(site, "reference", "index.html"), "<p>reference</p>")
        write(os.path.join(site, "index.html"), good_index)
        code, out = run(checker, site)
        expect(code == 0, f"a clean site passes (exit {code}): {out}")
        expect("0 broken" in out and "1 links to other sites" in out, f"the clean site's counts: {out}")

        broken = good_index.replace(
            "</body>",
            '<a href="reference/missing.html">missing page</a>'
            '<a href="reference/schemes.html#scheme-se9">missing anchor</a>'
            '<a href="#nowhere">missing anchor here</a>'
            '<a href="../../etc/passwd">out of the site</a>'
            '<script src="https://cdn.example.org/mathjax.js"></script>'
            '<link rel="stylesheet" href="//fonts.example.org/font.css"></body>')
        write(os.path.join(site, "index.html"), broken)
        code, out = run(checker, site)
        expect(code == 1, f"a broken site fails with 1 (exit {code})")
        for part in ["reference/missing.html: no file", "no anchor #scheme-se9 in reference/schemes.html",
                     "#nowhere: no anchor #nowhere in index.html", "../../etc/passwd leaves the site",
                     "https://cdn.example.org/mathjax.js\"> loads from the network",
                     "//fonts.example.org/font.css\"> loads from the network", "6 broken"]:
            expect(part in out, f"the report names: {part}\n{out}")

        os.remove(os.path.join(site, "index.html"))
        code, out = run(checker, site)
        expect(code == 2, f"a site without index.html is a usage error (exit {code})")

    for f in failures:
        print("FAILED:", f)
    print(f"test_check_links: {'failed' if failures else 'passed'}")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
