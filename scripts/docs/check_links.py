#!/usr/bin/python3
"""Checks the built documentation site for broken internal links and for network loads.

    check_links.py build/docs/html

Every href and src of every HTML page that is not an external URL must name a file of the
site, and its #fragment an id (or a name) in that file. Scripts, style sheets, images and
frames must come from the site itself, so that it works offline; links to other sites are
counted, not fetched. Exits 1 naming every broken link (page, target), 0 otherwise.
"""
import argparse
import html.parser
import os
import sys
import urllib.parse

# Elements whose URL the browser loads by itself (not a link the reader follows).
_LOADED = {("script", "src"), ("link", "href"), ("img", "src"), ("iframe", "src"), ("source", "src"),
           ("video", "src"), ("audio", "src"), ("embed", "src"), ("object", "data")}
_URL_ATTRS = {"href", "src", "data"}


class Page(html.parser.HTMLParser):
    """The ids and the outgoing URLs of one HTML page."""

    def __init__(self):
        super().__init__(convert_charrefs=True)
        self.ids = set()
        self.urls = []  # (tag, attribute, url)

    def handle_starttag(self, tag, attrs):
        for name, value in attrs:
            if value is None:
                continue
            if name == "id" or (tag == "a" and name == "name"):
                self.ids.add(value)
            elif name in _URL_ATTRS:
                if tag == "link" and name == "href" and dict(attrs).get("rel") in ("canonical",):
                    continue
                self.urls.append((tag, name, value))

    handle_startendtag = handle_starttag


def parse(path):
    page = Page()
    with open(path, encoding="utf-8", errors="replace") as f:
        page.feed(f.read())
    return page


def check_site(site):
    """Returns (problems, pages checked, internal links checked, external links)."""
    site = os.path.abspath(site)
    pages = {}
    for directory, _, files in os.walk(site):
        for name in files:
            if name.endswith(".html"):
                path = os.path.join(directory, name)
                pages[path] = parse(path)
    problems, internal, external = [], 0, 0
    for path, page in sorted(pages.items()):
        where = os.path.relpath(path, site)
        for tag, attr, url in page.urls:
            parts = urllib.parse.urlsplit(url)
            if parts.scheme in ("mailto", "data", "javascript"):
                continue
            if parts.scheme or url.startswith("//"):
                if (tag, attr) in _LOADED:
                    problems.append(f"{where}: <{tag} {attr}=\"{url}\"> loads from the network")
                external += 1
                continue
            internal += 1
            target = path if not parts.path else os.path.normpath(
                os.path.join(os.path.dirname(path), urllib.parse.unquote(parts.path)))
            if not target.startswith(site + os.sep) and target != site:
                problems.append(f"{where}: {url} leaves the site")
                continue
            if os.path.isdir(target):
                target = os.path.join(target, "index.html")
            if not os.path.isfile(target):
                problems.append(f"{where}: {url}: no file {os.path.relpath(target, site)}")
                continue
            fragment = urllib.parse.unquote(parts.fragment)
            if fragment and target.endswith(".html"):
                ids = pages[target].ids if target in pages else parse(target).ids
                if fragment not in ids:
                    problems.append(f"{where}: {url}: no anchor #{fragment} in {os.path.relpath(target, site)}")
    return problems, len(pages), internal, external


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("site", help="the built site (build/docs/html)")
    args = parser.parse_args()
    if not os.path.isfile(os.path.join(args.site, "index.html")):
        print(f"check_links: {args.site} has no index.html: build the site first", file=sys.stderr)
        return 2
    problems, pages, internal, external = check_site(args.site)
    for p in problems:
        print(f"check_links: {p}", file=sys.stderr)
    print(f"check_links: {pages} pages, {internal} internal links checked, {len(problems)} broken; "
          f"{external} links to other sites, not fetched")
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
