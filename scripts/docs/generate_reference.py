#!/usr/bin/python3
"""Writes the docs site's generated reference from what the built runner says about itself.

    generate_reference.py --tsi BUILD/bin/tsi --out docs/reference/generated

`tsi list --json` gives every registered model, reformulation, field and scheme with its
parameters (type, default, valid values, meaning) and each scheme's traits; `tsi list config
--json` gives the run config's sections and the runner's own keys. The pages of
docs/reference/ include the Markdown written here, so the reference cannot drift from the code.
Nothing here knows a model or a scheme by name.
"""
import argparse
import json
import os
import subprocess
import sys

# CommonMark lets a backslash escape any ASCII punctuation; these would otherwise start markup
# (dollarmath's $, a table's |, MyST's roles and targets).
_MARKUP = set("\\`*_[]<>|$#{}~!")


def text(value):
    """Plain text as Markdown that shows exactly that text."""
    return "".join("\\" + c if c in _MARKUP else c for c in str(value))


def sentence(value):
    """A summary as a sentence: capital first letter, a full stop at the end."""
    s = str(value).strip()
    s = s[:1].upper() + s[1:]
    return text(s if s.endswith((".", "!", "?")) else s + ".")


def code(value):
    """An inline code span, whatever backticks the value holds."""
    s = str(value)
    fence = "`"
    while fence in s:
        fence += "`"
    pad = " " if s.startswith("`") or s.endswith("`") else ""
    return f"{fence}{pad}{s}{pad}{fence}"


def default_of(param):
    value = param["default"]
    return "none" if value is None else code(json.dumps(value))


def anchor(kind, name):
    """A label other pages can reference: {ref}`scheme-se1`."""
    return f"{kind}-{name}".lower().replace("_", "-").replace(".", "-")


def provider(entry):
    """Where an entry comes from, without this machine's paths."""
    p = entry["provider"]
    return "the core" if p == "core" else code(os.path.basename(p))


def params_table(params, prefix=""):
    if not params:
        return "No parameters.\n"
    rows = ["| key | type | default | valid values | meaning |", "|---|---|---|---|---|"]
    for p in params:
        rows.append("| " + " | ".join([code(prefix + p["name"]), text(p["type"]), default_of(p),
                                       text(p["expected"]) or "any", text(p["description"])]) + " |")
    return "\n".join(rows) + "\n"


def yes(flag):
    return "yes" if flag else "no"


def aliases(entry):
    return ", ".join(code(a) for a in entry["aliases"])


def entry_header(kind, entry):
    out = [f"({anchor(kind, entry['name'])})=", f"## {code(entry['name'])}", "", sentence(entry["summary"]), ""]
    facts = []
    if entry["aliases"]:
        facts.append(f"aliases {aliases(entry)}")
    facts.append(f"provided by {provider(entry)}")
    said = "; ".join(facts)
    out += [said[0].upper() + said[1:] + ".", ""]
    return out


def models_page(listing):
    out = []
    for m in listing["models"]:
        out += entry_header("model", m)
        out += [f"Default `n_tau` (two-scale): {m['default_n_tau']}. "
                + ("It has a linear remainder R, integrated exactly; some schemes then need prepared data of a "
                   "higher order (the chart's last data column)." if m["linear_remainder"] else "No linear remainder."),
                "", params_table(m["params"], "model."), ""]
    return "\n".join(out)


def reformulations_page(listing):
    out = []
    for r in listing["reformulations"]:
        out += entry_header("reformulation", r)
        out += [params_table(r["params"], "reformulation."), ""]
    return "\n".join(out)


def fields_page(listing):
    out = []
    for f in listing["fields"]:
        out += entry_header("field", f)
        size = "any number of entries" if f["dim"] == 0 else f"{f['dim']} entries"
        out += [f"Takes {size}; {'time-dependent' if f['time_dependent'] else 'autonomous'}; "
                f"{'complex' if f['is_complex'] else 'real'}.", ""]
    return "\n".join(out)


def orders(t):
    """The scheme's order as `tsi list` words it: uniform, at a fixed eps, at resonances."""
    s = str(t["order"])
    if t["classical_order"] > t["order"]:
        s += f" ({t['classical_order']} at fixed eps)"
    return s


def resonant(t):
    r = t["resonant_order"]
    if r >= t["order"]:
        return "same"
    return str(r) if r > 0 else "bounded"


def data_orders(t):
    s = str(t["initial_data_order"])
    if t["remainder_data_order"] > t["initial_data_order"]:
        s += f" ({t['remainder_data_order']} with a remainder)"
    return s


def scheme_chart(listing):
    # Seven columns fit a page: the step's kind (one-step, multistep, adaptive) in one.
    rows = ["| scheme | order (uniform in eps) | at h ~ k pi eps | symmetric | implicit | step "
            "| data order | reformulations |",
            "|---|---|---|---|---|---|---|---|"]
    for s in listing["schemes"]:
        t = s["traits"]
        step = "adaptive" if t["adaptive"] else "multistep" if t["multistep"] else "one-step"
        rows.append("| " + " | ".join([
            f"{{ref}}`{s['name']} <{anchor('scheme', s['name'])}>`", orders(t), resonant(t), yes(t["symmetric"]),
            yes(t["implicit"]), step, data_orders(t), ", ".join(t["reformulations"])]) + " |")
    return "\n".join(rows) + "\n"


def schemes_page(listing):
    out = []
    for s in listing["schemes"]:
        t = s["traits"]
        out += entry_header("scheme", s)
        out += [f"Order {orders(t)}; at step-size resonances h ~ k pi eps: {resonant(t)}. "
                f"{'Symmetric' if t['symmetric'] else 'Not symmetric'}, {'implicit' if t['implicit'] else 'explicit'}"
                f"{', multistep' if t['multistep'] else ''}{', adaptive' if t['adaptive'] else ''}. "
                f"Prepared data of order {data_orders(t)}. Integrates: {', '.join(t['reformulations'])}.", "",
                params_table(s["params"], "scheme."), ""]
    return "\n".join(out)


def config_page(config):
    out = []
    for section in config:
        name = section["name"]
        out += [f"({anchor('config', name)})=", f"## {code(name)}", "", sentence(section["summary"]), ""]
        if "chosen_from" in section:
            kind = section["chosen_from"]
            out += [f"`{name}.name` selects one of the {{ref}}`{kind} <reference-{kind}>`; the section's other keys "
                    f"are that entry's parameters, listed there.", ""]
        if "params" in section:
            out += [params_table(section["params"], name + "."), ""]
    return "\n".join(out)


def run_json(tsi, *args):
    result = subprocess.run([tsi, *args, "--json"], check=True, capture_output=True, text=True)
    return json.loads(result.stdout)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--tsi", required=True, help="the built runner")
    parser.add_argument("--out", required=True, help="directory for the generated Markdown")
    args = parser.parse_args()
    listing = run_json(args.tsi, "list")
    config = run_json(args.tsi, "list", "config")["config"]
    pages = {"run-config.md": config_page(config), "models.md": models_page(listing),
             "reformulations.md": reformulations_page(listing), "fields.md": fields_page(listing),
             "schemes.md": schemes_page(listing), "scheme-chart.md": scheme_chart(listing)}
    os.makedirs(args.out, exist_ok=True)
    for name, body in pages.items():
        path = os.path.join(args.out, name)
        header = "<!-- generated by scripts/docs/generate_reference.py from the built tsi: do not edit -->\n\n"
        # rewritten only when changed, so that Sphinx rereads only the pages that include it
        new = header + body
        if not os.path.exists(path) or open(path, encoding="utf-8").read() != new:
            with open(path, "w", encoding="utf-8") as f:
                f.write(new)
    print(f"generate_reference: {len(pages)} pages in {args.out} ({len(listing['models'])} models, "
          f"{len(listing['schemes'])} schemes, {sum(len(s.get('params', [])) for s in config)} runner keys)")


if __name__ == "__main__":
    sys.exit(main())
