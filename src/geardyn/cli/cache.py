"""``geardyn cache``: what the disk cache holds, and clearing it."""

from __future__ import annotations

from typing import Annotated

import typer

from . import app
from ._common import console, handle_errors

cache_app = typer.Typer(help="What the disk cache holds (maps, FE bodies, simulations, figures), "
                             "and clearing it.", no_args_is_help=True)
app.add_typer(cache_app, name="cache")


def _mb(n: int) -> str:
    return f"{n / 1e6:.1f} MB"


def _when(t: float | None) -> str:
    import time

    return "-" if t is None else time.strftime("%Y-%m-%d %H:%M", time.localtime(t))


@cache_app.command("info")
@handle_errors
def info() -> None:
    """The cache folder, and its entries by kind: how many, their size [MB] and when the least
    and the most recently used entry was last used."""
    from rich.markup import escape
    from rich.table import Table

    from ..cache import Cache
    from ..cache_admin import cache_usage

    cache = Cache()
    usage = cache_usage(cache)
    state = "" if cache.enabled else " (GEARDYN_NO_CACHE is set: runs neither read nor write it)"
    console.print(f"cache folder: {escape(str(cache.root))}{state}", highlight=False,
                  soft_wrap=True)
    if not usage:
        console.print("empty", highlight=False)
        return
    table = Table("kind", "entries", "size", "least recently used", "last used")
    for u in usage:
        table.add_row(escape(u.kind), str(u.entries), _mb(u.bytes), _when(u.oldest),
                      _when(u.newest))
    table.add_row("all", str(sum(u.entries for u in usage)), _mb(sum(u.bytes for u in usage)),
                  _when(min((u.oldest for u in usage if u.oldest), default=None)),
                  _when(max((u.newest for u in usage if u.newest), default=None)),
                  style="bold")
    console.print(table)


@cache_app.command("clear")
@handle_errors
def clear(
    kind: Annotated[list[str] | None, typer.Option(
        "--kind", help="Only this kind (repeatable): stiffness, fe, simulation, figure... "
                       "(see geardyn cache info).", show_default=False)] = None,
    older_than: Annotated[str | None, typer.Option(
        "--older-than", help="Only entries not used for longer than this, e.g. '30 d', '12h' "
                             "(units s, min, h, d, w).", show_default=False)] = None,
    dry_run: Annotated[bool, typer.Option("--dry-run", help="Say what would be removed; "
                                                            "remove nothing.")] = False,
    yes: Annotated[bool, typer.Option("--yes", help="Remove without asking (required where there is "
                                                   "no terminal to ask in).")] = False,
) -> None:
    """Remove cache entries (all, or of some kinds, or unused for a while). A later run builds
    what it needs again. Entries in use by a running geardyn are left alone."""
    import sys

    from ..cache import Cache
    from ..cache_admin import parse_age, prune
    from ..errors import NOT_GIVEN, InputError

    cache = Cache()
    age = None if older_than is None else parse_age(older_than)
    kinds = tuple(kind) if kind else None
    plan = prune(cache, kinds=kinds, older_than=age, dry_run=True)
    what = f"{plan.entries} entries, {_mb(plan.bytes)}"
    if dry_run or plan.entries == 0:
        verb = "would remove" if dry_run else "nothing to remove:"
        detail = ", ".join(f"{k} {n} ({_mb(b)})" for k, (n, b) in sorted(plan.removed.items()))
        console.print(f"{verb} {what}" + (f": {detail}" if detail else "")
                      + (f"; {plan.in_use} in use, left alone" if plan.in_use else ""),
                      highlight=False, soft_wrap=True)
        return
    if not yes:
        if not sys.stdin.isatty():
            raise InputError("--yes", NOT_GIVEN, f"--yes to remove {what} from "
                             f"{cache.root} (or --dry-run to list them)")
        typer.confirm(f"remove {what} from {cache.root}?", abort=True)
    done = prune(cache, kinds=kinds, older_than=age)
    console.print(f"removed {done.entries} entries, {_mb(done.bytes)}"
                  + (f"; {done.in_use} in use, left alone" if done.in_use else "")
                  + (f"; {done.kept} kept" if done.kept else ""), highlight=False,
                  soft_wrap=True)
