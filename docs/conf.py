# Sphinx configuration of the tsi documentation site. Build it with ./scripts/build-docs.sh
# (Debian 12 packages only, offline; every warning is an error). Pages are MyST Markdown.
import os
import shutil
import sys

docs = os.path.dirname(os.path.abspath(__file__))
root = os.path.dirname(docs)
# The built tsi the site documents: its runner and plugins (the generated reference, the
# {program-output} directives), its Python module (the Python API). build-docs.sh sets it.
tsi_build = os.environ.get("TSI_DOCS_TSI_BUILD", os.path.join(root, "build"))
os.environ["PATH"] = os.pathsep.join([os.path.join(tsi_build, "bin"), os.path.join(root, "scripts", "docs"),
                                      os.environ.get("PATH", "")])
os.environ["PYTHONPATH"] = os.pathsep.join(p for p in [os.path.join(tsi_build, "python"),
                                                       os.environ.get("PYTHONPATH")] if p)
os.environ["TSI_SOURCE_DIR"] = root
os.environ["MPLBACKEND"] = "Agg"
os.environ.pop("TSI_PLUGIN_PATH", None)  # the shipped plugins alone, as the reference lists them
sys.path.insert(0, os.path.join(tsi_build, "python"))

project = "tsi"
author = "the tsi developers"
copyright = "2026, the tsi developers (BSD 3-Clause)"

extensions = [
    "myst_parser",
    "sphinx.ext.mathjax",
    "sphinx.ext.autodoc",
    "breathe",
    "sphinxcontrib.programoutput",
]
source_suffix = {".md": "markdown"}
smartquotes = False  # "exact" and --threads are typed as shown, not as “exact” and –threads
root_doc = "index"
# reference/generated/: Markdown that reference pages include ({include}), not pages of their own;
# snippets/: the commands pages show, run by the docs tests (docs/snippets/README.md).
exclude_patterns = ["reference/generated/**", "snippets/**"]

myst_enable_extensions = ["dollarmath", "amsmath", "colon_fence", "deflist"]
myst_heading_anchors = 3  # [text](page.md#a-heading) links to headings down to ###
myst_update_mathjax = False  # its settings are MathJax 3's; the site uses Debian's MathJax 2 below

# Equations render offline: Debian's MathJax (libjs-mathjax) is copied into the site
# (copy_mathjax below), so that pages work from file:// with no network.
mathjax_source = "/usr/share/javascript/mathjax"
mathjax_path = "mathjax/MathJax.js?config=TeX-AMS_CHTML"
mathjax2_config = {
    "tex2jax": {"inlineMath": [["\\(", "\\)"]], "displayMath": [["\\[", "\\]"]], "processEscapes": False},
    "CommonHTML": {"linebreaks": {"automatic": True}},
    "menuSettings": {"zoom": "Click"},
}
# What MathJax 2 loads for that configuration: the rest of the 54 MB package stays out.
mathjax_parts = ["MathJax.js", "config/TeX-AMS_CHTML.js", "extensions", "jax/input/TeX",
                 "jax/output/CommonHTML", "jax/output/PreviewHTML", "jax/element", "fonts/HTML-CSS/TeX/woff", "localization/en"]

breathe_projects = {"tsi": os.environ.get("TSI_DOXYGEN_XML", os.path.join(root, "build", "docs", "doxygen", "xml"))}
breathe_default_project = "tsi"
breathe_default_members = ("members", "undoc-members")
breathe_show_include = False  # the header is named in each section's title
cpp_index_common_prefix = ["tsi::"]

autodoc_member_order = "bysource"
autodoc_default_options = {"members": True, "show-inheritance": True}

# Nitpicky (-n): every reference must resolve, except to names of other libraries, which
# this site does not document and, offline, cannot link (no intersphinx).
nitpick_ignore_regex = [
    ("cpp:identifier", r"tsi(::algebra)?(::detail)?"),  # namespaces: the prefix of a documented name
    ("cpp:identifier", r"(std|Eigen|nlohmann|CLI|fmt)(::.*)?"),
    ("cpp:identifier", r"u?int(8|16|32|64)_t|size_t|ptrdiff_t|Json(::.*)?"),
    ("py:class", r"(numpy|np|pandas|matplotlib|os)\..*"),
]

html_theme = "furo"
html_title = "tsi"
html_static_path = ["_static"]
html_css_files = ["tsi.css"]
html_show_sourcelink = False
html_copy_source = False


def copy_mathjax(app, exception):
    """Copies the parts of Debian's MathJax the site loads into _static/mathjax."""
    if exception is not None or app.builder.format != "html":
        return
    target = os.path.join(app.outdir, "_static", "mathjax")
    for part in mathjax_parts:
        source, dest = os.path.join(mathjax_source, part), os.path.join(target, part)
        os.makedirs(os.path.dirname(dest), exist_ok=True)
        if os.path.isdir(source):
            shutil.copytree(source, dest, dirs_exist_ok=True)
        else:
            shutil.copy2(source, dest)


def docstring_as_written(app, what, name, obj, options, lines):
    """The package's docstrings are plain text (examples indented, `x` for code), not reST:
    shown as written, in a literal block, rather than misread as markup."""
    if lines:
        lines[:] = ["::", ""] + ["    " + line for line in lines] + [""]


def setup(app):
    if not os.path.isfile(os.path.join(mathjax_source, "MathJax.js")):
        raise RuntimeError(f"MathJax not found in {mathjax_source}: install libjs-mathjax (scripts/build-docs.sh does)")
    app.connect("build-finished", copy_mathjax)
    app.connect("autodoc-process-docstring", docstring_as_written)
