"""railproof testgen: specification checks, SPIN runs, vector generation, traceability."""
__version__ = "0.1.0"

SPEC_DIR = "spec/ directory"  # the help of the --spec option most commands take


def add_command(sub, name, run, help, description=None, **options):
    """Add the command `name` to the sub-parsers `sub` (see __main__); `run(args)` runs it.

    Each keyword option becomes `--<name>` (underscores as dashes), in the order given: a
    string is a required option with that help, a dict the arguments of add_argument. The
    description may be spread over lines; it is folded to one line (the help wraps it)."""
    if description is not None:
        description = " ".join(description.split())
    p = sub.add_parser(name, help=help, description=description)
    for key, spec in options.items():
        flag = "--" + key.replace("_", "-")
        if isinstance(spec, str):
            p.add_argument(flag, required=True, help=spec)
        else:
            p.add_argument(flag, **spec)
    p.set_defaults(func=run)
    return p
