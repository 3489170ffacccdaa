"""Command-line interface: ``python -m replication status|show|cite|index``, ``--version``."""

from __future__ import annotations

import argparse
import sys

from replication._meta import __version__, repository_url
from replication.registry import reproduction as rp


def _cmd_status(args) -> int:
    status, register = rp.build_index(write=args.write)
    if args.source:
        status = status[status["source"] == args.source]
        register = register[register["source"] == args.source]
    fail = rp.failing_artifacts(status)
    if len(fail):
        n = int(fail["not_reproduced"].sum())
        print(f"== not reproduced: {len(fail)} paper artifacts hold {n} not-reproduced rows")
        for _, r in fail.iterrows():
            print(f"{r['id']}  {r['label']}\n    {r['reason']}\n    tables: {r['tables']}")
        print()
    elif args.failing:
        print("no paper artifact holds a not-reproduced row")
    if args.failing:
        return 0
    width = max(len(i) for i in status["id"]) if len(status) else 10
    for kind, title in (("paper", "artifacts of the four documents"), ("supplementary", "supplementary checks")):
        part = status[status["kind"] == kind]
        if not len(part):
            continue
        print(f"== {title} (cite or show a table id of the last column)")
        print(f"{'id':<{width}}  {'status':<28} rows  tables")
        for _, r in part.iterrows():
            print(f"{r['id']:<{width}}  {rp.status_label(r):<28} {r['rows']:>4}  {r['tables'] or '-'}")
        print()
    for line in rp.status_tally(status).values():
        print(line)
    kinds = register["kind"].value_counts()
    print(f"register{' of ' + args.source if args.source else ''}: {int(kinds.get('erratum', 0))} errata, "
          f"{int(kinds.get('inconsistent', 0))} inconsistencies (tables/register.csv)")
    return 0


def _cmd_show(args) -> int:
    tables = rp.resolve_table_ids(args.id)
    texts = {}
    for table_id in tables:                      # every table readable (CSV, sidecar, export) before any is printed
        rp.load_table(table_id)
        export = rp.tables_dir() / f"{table_id}.{args.format}"
        fix = "rebuild the exports with replication.registry.reproduction.refresh_exports(), or restore it (git checkout)"
        if args.format != "csv" and not export.is_file():
            raise rp.RegistryError(f"{export} does not exist: {fix}")
        if args.format != "csv":
            try:
                texts[table_id] = export.read_text(encoding="utf-8")
            except UnicodeDecodeError as exc:
                raise rp.RegistryError(f"{export} is not UTF-8 ({exc.reason} at byte {exc.start}): {fix}") from None
    for i, table_id in enumerate(tables):
        if len(tables) > 1:                      # an artifact covered by several tables: each in turn
            heading = f"{table_id} ({i + 1} of {len(tables)} tables covering {args.id})"
            sys.stdout.write(("\n" if i else "") + {"md": f"## {heading}\n\n", "tex": f"% {heading}\n",
                                                     "csv": f"# {heading}\n"}[args.format])
        if args.format == "csv":
            sys.stdout.write(rp.read_table(table_id).to_csv(index=False, lineterminator="\n"))
        else:
            sys.stdout.write(texts[table_id])
    return 0


def _cmd_cite(args) -> int:
    sys.stdout.write(rp.bibtex_for(args.id))
    return 0


def _cmd_index(args) -> int:
    status, register = rp.build_index(write=True)
    print(f"wrote tables/status.csv ({len(status)} artifacts) and tables/register.csv ({len(register)} errata and "
          "inconsistencies)")
    return 0


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m replication", description=__doc__)
    parser.add_argument("--version", action="version",
                        version=f"replication {__version__} ({repository_url()})")
    sub = parser.add_subparsers(dest="command", required=True)
    p = sub.add_parser("status", help="the reproduction dashboard: one line per seed artifact")
    p.add_argument("--source", choices=rp.SOURCE_KEYS + ("toolkit",), help="only one source document")
    p.add_argument("--write", action="store_true", help="also rewrite tables/status.csv and register.csv")
    p.add_argument("--failing", action="store_true",
                   help="only the paper artifacts holding not-reproduced rows, each with its reason")
    p.set_defaults(func=_cmd_status)
    p = sub.add_parser("show", help="print an exported table (every table covering an artifact id)")
    p.add_argument("id", help="an id printed by `status`: a table id, e.g. chen2019-eq-3-1, or an artifact id")
    p.add_argument("--format", choices=("csv", "md", "tex"), default="md")
    p.set_defaults(func=_cmd_show)
    p = sub.add_parser("cite", help="BibTeX for an exported table (one entry per table covering an artifact id)")
    p.add_argument("id", help="an id printed by `status`")
    p.set_defaults(func=_cmd_cite)
    p = sub.add_parser("index", help="check the verdict rule, rebuild tables/status.csv and tables/register.csv")
    p.set_defaults(func=_cmd_index)
    args = parser.parse_args(argv)
    try:
        return args.func(args)
    except rp.RegistryError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2
    except BrokenPipeError:                      # e.g. `python -m replication status | head`
        sys.stderr.close()
        return 0
    except OSError as exc:                       # a file of the tables that cannot be read or written
        where = f"{exc.filename}: " if exc.filename else ""
        print(f"error: {where}{exc.strerror or exc}; check the file's permissions and REPLICATION_ROOT", file=sys.stderr)
        return 2


if __name__ == "__main__":
    sys.exit(main())
