"""The cache option of every command line: ``--no-compile-cache``."""

from __future__ import annotations

from ignjax.cache.folder import CACHE_DIR_ENV, NO_CACHE_ENV


def add_cache_arguments(parser) -> None:
    """The cache option every command line shares (an argparse parser)."""
    parser.add_argument("--no-compile-cache", action="store_true",
                        help="compile every program instead of loading it from JAX's persistent compilation cache "
                             f"(on by default, in the ignjax cache folder: {CACHE_DIR_ENV} moves it, "
                             f"{NO_CACHE_ENV}=1 turns every cache off)")


def apply_cache_arguments(args) -> None:
    """Act on :func:`add_cache_arguments`'s option, before any program compiles."""
    from ignjax.cache.compile import use_compile_cache  # loads JAX: not at the top, --help does not need it

    use_compile_cache(not args.no_compile_cache)


def prefetch_command_programs(command: str, args) -> int:
    """Start loading ahead the stored programs the last run of ``command``
    with the same options used (the options less ``out``, so a run written
    elsewhere counts as the same run;
    :func:`~ignjax.cache.programs.prefetch_programs`: the loads run in
    background threads from this call on). Call it once JAX's runtime has
    joined (a run of several processes) and not in a launcher. Returns how
    many loads started."""
    from ignjax.cache.programs import prefetch_programs

    return prefetch_programs((command, sorted((k, repr(v)) for k, v in vars(args).items() if k != "out")))


__all__ = ["add_cache_arguments", "apply_cache_arguments", "prefetch_command_programs"]
