"""`suds-exp`: the command-line face of the suds_exp library.

Each command parses options and calls one library function; the work lives in
`suds_exp`. User errors (`SudsError`) print one line and exit with status 2.
"""

from __future__ import annotations

import functools
import inspect
import typing
from pathlib import Path
from typing import TYPE_CHECKING, Annotated

import typer
import typer.core
from rich.markup import escape

from suds_exp import __version__, console
from suds_exp.commands.messages import user_message
from suds_exp.errors import ConfigError, SudsError

if TYPE_CHECKING:
    from suds_exp.store import Store


def _source_help(text: str | None) -> str | None:
    """A help text as its source reads: rich markup escaped (``suds-exp[pose]`` stays), a
    prose paragraph's line breaks joined (rich keeps them), an ``Examples:`` paragraph kept
    a command a line."""
    if not text:
        return text
    paragraphs = inspect.cleandoc(text).split("\n\n")
    kept = [p if p.startswith("Examples:") else " ".join(p.split("\n")) for p in paragraphs]
    return escape("\n\n".join(kept))


#: metavars of options that give none, by type (click's words): a flag shows no value
VALUE_NAMES = {int: "INTEGER", float: "FLOAT", str: "TEXT", Path: "PATH"}


def _value_name(param: typer.core.TyperOption) -> str:
    kind = param.type_descriptor.annotation
    if typing.get_origin(kind) is list:
        (kind,) = typing.get_args(kind)
    return VALUE_NAMES.get(kind, "VALUE")


class _Argument(typer.core.TyperArgument):
    # its name column already shows the metavar; typer would add the Python type
    def display_type_rich(self, ctx):
        return None


class _SourceHelp:
    """Help that shows what the source says: flags without a type label, values with a
    metavar, arguments in upper case, brackets and examples kept."""

    def __init__(self, *args, **kwargs):
        super().__init__(*args, **kwargs)
        self.help = _source_help(self.help)
        for param in self.params:
            _label(param)

    def get_help_option(self, ctx):
        option = super().get_help_option(ctx)
        if option is not None:
            _label(option)
        return option


def _label(param) -> None:
    param.help = _source_help(getattr(param, "help", None))
    if isinstance(param, typer.core.TyperArgument):
        param.__class__ = _Argument
        param.metavar = param.metavar or param.name.upper()
    elif param.metavar is None:
        param.metavar = "" if param.is_flag else _value_name(param)


class Command(_SourceHelp, typer.core.TyperCommand):
    def collect_usage_pieces(self, ctx):
        # click's convention: NAME required, [NAME] optional, NAME... repeated
        pieces = [self.options_metavar] if self.options_metavar else []
        for param in self.get_params(ctx):
            if isinstance(param, typer.core.TyperArgument):
                name = param.metavar + ("..." if param.nargs != 1 else "")
                pieces.append(name if param.required else f"[{name}]")
        return pieces


class Group(_SourceHelp, typer.core.TyperGroup):
    pass


def sub_app(help: str) -> typer.Typer:
    """A group of commands (``suds-exp gait ...``)."""
    return typer.Typer(help=help, no_args_is_help=True, cls=Group)


app = typer.Typer(
    name="suds-exp",
    help="Learn the motility map of an under-actuated robot from motion capture, "
    "and run the paper's bootstrap experiment on it.",
    no_args_is_help=True,
    add_completion=False,
    pretty_exceptions_enable=False,
    cls=Group,
)


def option(help: str, *flags: str, metavar: str | None = None, **kwargs):
    """`typer.Option` with its help first, so that a declaration fits one line."""
    return typer.Option(*flags, help=help, metavar=metavar, **kwargs)


DbOption = Annotated[
    Path | None,
    option("DuckDB file (default: ./suds.duckdb, or $SUDS_DB).", "--db", envvar="SUDS_DB"),
]
JsonOption = Annotated[bool, option("Print one JSON document on stdout.", "--json")]
CsvOption = Annotated[bool, option("Print the table as CSV on stdout.", "--csv")]


def old_name(flag: str, new: str):
    """A hidden option: ``flag``, the name ``new`` had before the commands shared one
    vocabulary (kept for one release; the changelog lists them)."""
    return typer.Option(flag, hidden=True, help=f"Old name of {new}.")


def either(value, old):
    """The value given under the old name when there was one, else the new name's."""
    return value if old is None else old


QuietOption = Annotated[bool, option("No progress bar.", "--quiet", "-q")]


# Options that several commands take: declared once, so that they are named, written and
# explained alike everywhere (a command's own help may say more in its docstring).
PrepOption = Annotated[
    str | None, option("Preprocessing version (default: the only one).", metavar="VERSION")
]
TrialsOption = Annotated[
    str | None, option("Trial ids, e.g. 1,2,5-8 (default: all).", "--trials", metavar="IDS")
]
ModelOption = Annotated[
    str, option("Learner, e.g. GMR, MLP, GMR+SUDS (suds_exp.models).", metavar="LEARNER")
]
LearnerAlias = Annotated[str | None, old_name("--learner", "--model")]
FreqOption = Annotated[str, option("Gait frequency, Hz (one value, e.g. 1/2).", metavar="HZ")]
FreqAlias = Annotated[str | None, old_name("--freq", "--freqs")]
BootAlias = Annotated[int | None, old_name("--boot", "--boots")]
TargetFreqsOption = Annotated[
    str | None, option("Target frequencies, Hz (default 1/2).", "--freqs", metavar="HZ,...")
]
TargetOption = Annotated[
    list[Path] | None, option("Target gait file (CSV or TOML); repeatable.", metavar="FILE")
]
CampaignArgument = Annotated[str, typer.Argument(help="Campaign name.")]
GridOption = Annotated[int, option("Points per joint axis.", metavar="N")]
RangeOption = Annotated[float, option("Half range of phi1, phi2 (rad).", "--range", metavar="RAD")]
JobsOption = Annotated[
    int, option("Worker processes (-1: all cores).", "--jobs", "-j", metavar="N")
]


def command(*args, flags: dict[str, str] | None = None, on: typer.Typer | None = None, **kwargs):
    """`app.command` (or ``on``'s, a sub-app) that turns a `SudsError` into one line on
    stderr and its exit code (2; 3 for a lost cluster); ``flags`` maps this command's
    library parameters to flags where `flag` would not."""

    def wrap(fn):
        @functools.wraps(fn)
        def run(*a, **kw):
            try:
                _one_output(kw)
                return fn(*a, **kw)
            except SudsError as exc:
                console.err.print(
                    f"[red]error:[/red] {user_message(exc, flags)}", markup=True, highlight=False
                )
                raise typer.Exit(exc.exit_code) from None
            except OSError as exc:
                # a file-system error the library did not foresee (disk full while a
                # report is written...): its path and reason, not a traceback
                where = f"{exc.filename}: " if exc.filename else ""
                reason = (exc.strerror or str(exc)).lower()
                console.err.print(
                    f"[red]error:[/red] {where}{reason}", markup=True, highlight=False
                )
                raise typer.Exit(2) from None
            except KeyboardInterrupt:
                # every write is one transaction: what was stored stays, nothing is half
                console.err.print(
                    "stopped (Ctrl-C): what was stored is kept; run the same command again "
                    "to continue",
                    highlight=False,
                )
                raise typer.Exit(130) from None

        return (on or app).command(*args, cls=Command, **kwargs)(run)

    return wrap


def _one_output(options: dict) -> None:
    """Refuse output flags that contradict: each of --json and --csv prints the whole
    output, and --table picks the table --csv prints (without it, it would be dropped)."""
    if options.get("json_") and options.get("csv"):
        raise ConfigError("--json and --csv each print the whole output: give one of them")
    if options.get("table") is not None and not options.get("csv"):
        raise ConfigError("--table goes with --csv: it picks the table printed as CSV")


def _print_version(value: bool) -> None:
    if value:
        console.out.print(f"suds-exp {__version__}")
        raise typer.Exit()


@app.callback()
def main(
    version: Annotated[
        bool,
        option("Print the version and exit.", "--version", callback=_print_version, is_eager=True),
    ] = False,
) -> None:
    # the options of `suds-exp` itself, before any command; the help text is the app's
    pass


def db_path(db: Path | None) -> Path:
    """The database file: ``--db``, else ``$SUDS_DB`` or ./suds.duckdb."""
    from suds_exp.store.engine import default_db_path

    return db if db is not None else default_db_path()


def open_store(db: Path | None) -> Store:
    # imported here: `--version` and `--help` need neither SQLAlchemy nor pandas
    from suds_exp.store import Store, default_db_path

    return Store(db if db is not None else default_db_path())


@command()
def init(db: DbOption = None, json_: JsonOption = False) -> None:
    """Create the database, or upgrade it to the latest schema.

    Examples:
      suds-exp init --db lab.duckdb
    """
    store = open_store(db)
    applied = store.upgrade()
    if json_:
        console.print_json({"db": str(store.path), "applied": applied})
        return
    console.out.print(
        f"{store.path}: " + (f"applied {', '.join(applied)}" if applied else "up to date")
    )


@command()
def ingest(
    paths: Annotated[list[Path] | None, typer.Argument(help="Capture files or folders.")] = None,
    manifest: Annotated[Path | None, option("CSV file,gait,frequency_hz,repeat,notes.")] = None,
    layout: Annotated[Path | None, option("CSV role,marker for the 11 roles.")] = None,
    software: Annotated[
        str | None,
        option(
            "Keypoint files' tracker: deeplabcut, sleap, lightning-pose, anipose "
            "(default: told by the file)."
        ),
    ] = None,
    fps: Annotated[
        float | None, option("Keypoint files' frame rate, when the file lacks it.")
    ] = None,
    mm_per_px: Annotated[float | None, option("Scale of 2-D keypoints, mm per pixel.")] = None,
    confidence_threshold: Annotated[
        float | None,
        option("Keypoints below this confidence are missing (default 0.6)."),
    ] = None,
    experiment: Annotated[
        Path | None, option("TOML of the condition axes (default: the paper's).")
    ] = None,
    db: DbOption = None,
    json_: JsonOption = False,
    quiet: QuietOption = False,
) -> None:
    """Ingest QTM TSV, C3D, Vicon Nexus / Motive / marker CSV and TRC files, and keypoint
    files of DeepLabCut, SLEAP, Lightning Pose and Anipose (needs suds-exp[pose]).

    Each file is one transaction; a bad file is reported in one line and the others are
    still stored (exit status 2 at the end); a file already stored is skipped. Keypoint
    files take --fps and --mm-per-px when the file does not say them.

    Examples:
      suds-exp ingest sim-data --manifest sim-data/manifest.csv
    """
    from suds_exp.commands.ingest import print_ingest
    from suds_exp.experiment import load_design
    from suds_exp.ingest import PoseOptions, ingest_paths

    design = load_design(experiment)
    results = ingest_paths(
        open_store(db),
        paths or [],
        manifest,
        layout,
        progress=not (quiet or json_),
        keep_going=True,
        pose=PoseOptions(software, fps, mm_per_px, confidence_threshold),
        design=design,
    )
    if print_ingest(results, json_):
        raise typer.Exit(2)


@command()
def trials(db: DbOption = None, json_: JsonOption = False, csv: CsvOption = False) -> None:
    """List the trials and their conditions.

    Examples:
      suds-exp trials
      suds-exp trials --json
      suds-exp trials --csv
    """
    from suds_exp.commands.ingest import print_trials
    from suds_exp.store.rows import trial_rows

    print_trials(trial_rows(db_path(db)), json_, csv)


@command()
def sql(
    query: Annotated[str, typer.Argument(help="SQL to run on a read-only connection.")],
    db: DbOption = None,
    json_: JsonOption = False,
    csv: CsvOption = False,
) -> None:
    """Run a read-only SQL query and print the result; statements that write are refused.

    Tables and views: docs/reference/database.md of the documentation.

    Examples:
      suds-exp sql "SELECT gait, count(*) AS n FROM trials GROUP BY gait"
      suds-exp sql "SELECT id, name FROM prep_versions" --json
    """
    from suds_exp.store.rows import query_rows

    rows = query_rows(db_path(db), query)
    if json_:
        console.print_json(rows)
    elif csv:
        console.print_csv(rows)
    else:
        console.print_rows(rows)


EffectOption = Annotated[
    list[str] | None,
    option(
        "A simulator effect NAME=VALUE (or NAME.PARAM=VALUE, on, off); repeatable.",
        "--effect",
        metavar="NAME=VALUE",
    ),
]
ScheduleOption = Annotated[
    list[str] | None,
    option(
        "A simulator effect NAME=VALUE (or NAME.PARAM=VALUE, on, off), or its schedule "
        "NAME=VALUE@TIMEs, e.g. flippers=locked@40s; repeatable.",
        "--effect",
        metavar="NAME=VALUE[@T]",
    ),
]
SimConfigOption = Annotated[
    Path | None, option("Simulator config (.toml or .json).", "--config", metavar="FILE")
]


@command(flags={"frequencies_hz": "--freqs"})
def simulate(
    out: Annotated[Path, option("Folder for TSV, truth Parquet and manifest.")],
    config: SimConfigOption = None,
    gaits: Annotated[
        str | None, option("Comma list, e.g. S+,O (default: all five).", metavar="GAITS")
    ] = None,
    freqs: Annotated[
        str | None, option("Hz, comma list (default: 1/3,1/2,1).", metavar="HZ,...")
    ] = None,
    repeats: Annotated[int, option("Trials per condition.")] = 4,
    cycles: Annotated[
        str | None,
        option("Cycles per trial MIN:MAX (default: 10:30).", metavar="MIN:MAX"),
    ] = None,
    seed: Annotated[int, option("Same seed, same files.")] = 0,
    effect: ScheduleOption = None,
    ingest: Annotated[bool, option("Ingest the result into --db.", "--ingest")] = False,
    gait_file: Annotated[
        Path | None,
        option("A gait file (CSV phase_rad,phi1_rad,phi2_rad or Fourier TOML)."),
    ] = None,
    db: DbOption = None,
    json_: JsonOption = False,
    quiet: QuietOption = False,
) -> None:
    """Simulate the swimmer and write QTM TSV captures, truth Parquet files and a manifest.

    The first run after an install compiles the simulator's kernels once (numba).

    Examples:
      suds-exp simulate --out sim-o --gaits O --freqs 1/2 --repeats 1 --cycles 3
      suds-exp simulate --out damped --gaits O --freqs 1/2 --repeats 1 --cycles 3 \\
        --effect hinge_damping=on
      suds-exp simulate --out ell --gait-file ellipse.toml --freqs 1/2 --repeats 1 --cycles 3 \\
        --ingest
    """
    from suds_exp.commands.simulate import simulate_options, simulate_text

    summary = simulate_options(
        out,
        config,
        gaits,
        freqs,
        repeats,
        cycles,
        seed,
        effect or [],
        gait_file,
        store=open_store(db) if ingest else None,
        progress=not (quiet or json_),
    )
    if json_:
        console.print_json(summary)
    else:
        console.out.print(simulate_text(summary))


@command(flags={"half_range": "--range"})
def connection(
    out: Annotated[Path, option("CSV file; figures go beside it (_vx/_vy/_wz.png).")],
    grid: GridOption = 21,
    range_: RangeOption = 2.5,
    geometry: Annotated[str, option("robot or classic (3 equal links).")] = "robot",
    config: SimConfigOption = None,
    effect: EffectOption = None,
    json_: JsonOption = False,
) -> None:
    """Local connection with flippers locked: body velocity per unit joint rate on a grid.

    The grid is --grid points per joint over [-RANGE, RANGE] rad.

    Examples:
      suds-exp connection --out reports/connection.csv --geometry classic --grid 11
    """
    from suds_exp.commands.simulate import build_config, connection_command

    summary = connection_command(out, grid, range_, geometry, build_config(config, effect or []))
    if json_:
        console.print_json(summary)
    else:
        console.out.print(f"wrote {summary['csv']} and {len(summary['figures'])} figures")


@command()
def effects(
    config: SimConfigOption = None,
    effect: EffectOption = None,
    json_: JsonOption = False,
    csv: CsvOption = False,
) -> None:
    """List the simulator's named effects: parameters, units, nominal values, ranges.

    With --config and --effect, the values of that model.

    Examples:
      suds-exp effects
      suds-exp effects --effect hinge_damping=on --json
      suds-exp effects --csv
    """
    from suds_exp.commands.simulate import build_config, effects_table
    from suds_exp.sim import effect_library

    model = build_config(config, effect or [])
    if json_:
        console.print_json(effect_library(model))
    elif csv:
        console.print_csv(effects_table(model))
    else:
        console.print_frame(effects_table(model), title="effects (* = main)")


@command()
def preprocess(
    name: Annotated[str | None, option("Name of a new version (default: v<id>).")] = None,
    param: Annotated[
        list[str] | None,
        option("KEY=VALUE over the defaults; repeatable.", "--param", metavar="KEY=VALUE"),
    ] = None,
    trials_: TrialsOption = None,
    list_: Annotated[bool, option("List the versions and exit.", "--list")] = False,
    body: Annotated[
        str | None,
        option("Body description: a TOML file, or 'swimmer' (the default body)."),
    ] = None,
    preset: Annotated[
        str | None,
        option("Named parameter set under --param: default | paper (the paper's own)."),
    ] = None,
    db: DbOption = None,
    json_: JsonOption = False,
    csv: Annotated[bool, option("With --list: the versions as CSV.", "--csv")] = False,
    quiet: QuietOption = False,
) -> None:
    """Turn markers into samples (shape, phase, body velocity) as a stored version.

    The same parameters are the same version: re-running skips the trials already done.
    --preset paper is the paper's own processing; --body FILE.toml describes another body
    (a marker chain: shape modes of chord angles).

    Examples:
      suds-exp preprocess --name smooth --param sg_window_cycles=0.15 --trials 1-2
      suds-exp preprocess --preset paper --name paper
      suds-exp preprocess --list
      suds-exp preprocess --list --csv
    """
    from suds_exp.commands.preprocess import preprocess_command, preprocess_text, print_versions

    if csv and not list_:
        raise ConfigError("--csv goes with --list: it prints the versions as CSV")
    store = open_store(db)
    if list_:
        print_versions(store, json_, csv)
        return
    result = preprocess_command(
        store, name, param or [], trials_, body, preset, progress=not (quiet or json_)
    )
    if json_:
        console.print_json(result.to_dict())
    else:
        console.out.print(preprocess_text(result))
    for line in result.warnings:
        console.err.print(f"warning: {line}")


CampaignModelsOption = Annotated[
    str | None,
    option(
        "Learners, comma-separated (default: the paper's five); MLP, GBT, kNN, KRR "
        "(+SUDS), sklearn:ClassName (+SUDS); survey = the five and the baselines.",
        metavar="LEARNERS",
    ),
]
ModelParamOption = Annotated[
    list[str] | None,
    option(
        "NAME.KEY=VALUE for a learner of --models, e.g. MLP.alpha=0.01.", metavar="NAME.KEY=VALUE"
    ),
]
SkipInfeasibleOption = Annotated[
    bool | None,
    option(
        "Leave out the (condition, training size) cells the data cannot supply "
        "instead of refusing the campaign; stored in its definition.",
        "--skip-infeasible/--no-skip-infeasible",
    ),
]


@command()
def run(
    name: Annotated[str, typer.Argument(help="Campaign name (created, or continued).")],
    prep: PrepOption = None,
    models: CampaignModelsOption = None,
    boots: Annotated[int | None, option("Draws per (train, test) pair (default 10).")] = None,
    train_cycles: Annotated[
        int | None, option("Training (and test) cycles of the main grid (default 30).")
    ] = None,
    sweep: Annotated[
        str | None,
        option(
            "Sample-efficiency sweep on same-condition pairs: 1-10,21,48 or paper.",
            metavar="CYCLES",
        ),
    ] = None,
    train_conditions: Annotated[
        str | None,
        option("GAIT@FREQ, GAIT or @FREQ, comma-separated (default: all).", metavar="CONDITIONS"),
    ] = None,
    test_conditions: Annotated[
        str | None, option("As --train-conditions.", metavar="CONDITIONS")
    ] = None,
    mode: Annotated[
        str | None,
        option("SUDS learners: measured or rollout (default measured).", metavar="MODE"),
    ] = None,
    model_param: ModelParamOption = None,
    skip_infeasible: SkipInfeasibleOption = None,
    jobs: JobsOption = 1,
    backend: Annotated[str, option("loky (this machine) or dask.", metavar="NAME")] = "loky",
    scheduler: Annotated[
        str | None,
        option("dask scheduler address, e.g. tcp://host:8786.", metavar="URL"),
    ] = None,
    db: DbOption = None,
    json_: JsonOption = False,
    quiet: QuietOption = False,
) -> None:
    """Create or continue a bootstrap campaign; Ctrl-C stops after saving finished jobs.

    An option left out of a continued campaign takes its stored value; a different value
    is refused. The paper's campaign on its design: suds-exp run paper --sweep paper -j 2.

    Examples:
      suds-exp run quick --models GMR,kNN --boots 2 --train-cycles 2 -j 2
      suds-exp run first --json
    """
    from suds_exp.campaign import run_campaign
    from suds_exp.commands import campaign

    options = campaign.parse_campaign_options(
        prep=prep,
        models=models,
        boots=boots,
        train_cycles=train_cycles,
        sweep=sweep,
        train_conditions=train_conditions,
        test_conditions=test_conditions,
        mode=mode,
        model_params=model_param,
        skip_infeasible=skip_infeasible,
    )
    summary = run_campaign(
        open_store(db),
        name,
        options,
        jobs=jobs,
        backend=backend,
        scheduler=scheduler,
        progress=not (quiet or json_),
    )
    if json_:
        console.print_json(summary.to_dict())
    else:
        console.out.print(summary.message())
    if summary.interrupted:
        raise typer.Exit(130)


@command(flags={"n_boot": "--boots"})
def survey(
    name: Annotated[
        str, typer.Argument(help="Campaign with a --sweep and/or a main grid of cross pairs.")
    ],
    cycles: Annotated[int, option("Main grid size: GMR's error target.")] = 30,
    versus: Annotated[str, option("Learner whose data need is set against GMR's.")] = "MLP",
    boots: Annotated[int, option("Bootstrap resamples of the ratio.")] = 1000,
    n_boot: Annotated[int | None, old_name("--n-boot", "--boots")] = None,
    db: DbOption = None,
    json_: JsonOption = False,
    csv: CsvOption = False,
    table: Annotated[
        str | None,
        option(
            "With --csv: cycles (cycles to target, the default) | timing | glm.", show_default=False
        ),
    ] = None,
) -> None:
    """Data each learner needs and its speed: cycles to reach x1.25 of its own largest-sweep
    error and GMR's 30-cycle error, per frequency, and the VERSUS/GMR data ratio (from a
    sweep); the GLM with the learner as a factor (from a main grid's cross pairs).

    The full survey: suds-exp run s --models survey --sweep 1,2,4,8,16,30,48.

    Examples:
      suds-exp run s --models GMR,MLP --sweep 1,2 --train-cycles 2 --boots 2 \\
        && suds-exp survey s --cycles 2 --boots 200 \\
        && suds-exp survey s --cycles 2 --boots 200 --csv --table timing
    """
    from suds_exp.analysis.survey import survey_json, survey_tables
    from suds_exp.commands.survey import print_survey, survey_frame

    tables = survey_tables(open_store(db), name, cycles, either(boots, n_boot), versus)
    if csv:
        console.print_csv(survey_frame(tables, table or "cycles"))
    elif json_:
        console.print_json(survey_json(tables))
    else:
        print_survey(tables, cycles)


@command()
def status(
    name: CampaignArgument,
    db: DbOption = None,
    json_: JsonOption = False,
    csv: CsvOption = False,
) -> None:
    """Jobs done / total per learner, rate and time left of a campaign (also while it runs).

    Examples:
      suds-exp status first
      suds-exp status first --json
      suds-exp status first --csv
    """
    from suds_exp.campaign import campaign_status
    from suds_exp.commands.campaign import print_status, status_rows

    report = campaign_status(open_store(db), name)
    if json_:
        console.print_json(report)
    elif csv:
        console.print_csv(status_rows(report))
    else:
        print_status(report)


@command(flags={"n_cycles": "--cycles", "paper_dir": "--paper", "n_boot": "--boots"})
def report(
    name: CampaignArgument,
    out: Annotated[Path | None, option("Folder (default: reports/NAME).")] = None,
    cycles: Annotated[
        int | None, option("Training size of box plots and GLMs (default: most common).")
    ] = None,
    pairs: Annotated[
        str, option("Spread/efficiency pairs: same-condition or same-frequency.")
    ] = "same-condition",
    paper: Annotated[
        Path | None, option("Folder of the paper's glm_table.csv and iqr_table.csv.")
    ] = None,
    experiment: Annotated[
        Path | None,
        option("TOML of the condition axes (default: the one stored at ingest)."),
    ] = None,
    boots: Annotated[int, option("Bootstrap replicates of the findings' intervals.")] = 400,
    db: DbOption = None,
    json_: JsonOption = False,
) -> None:
    """Write a campaign's report: box plots, GLM, IQR and slope tables, paper comparison.

    Open index.html of the folder in a browser.

    Examples:
      suds-exp report first --out reports/first
    """
    from suds_exp.analysis import write_report
    from suds_exp.commands.report import report_document
    from suds_exp.experiment import load_design

    design = load_design(experiment) if experiment is not None else None
    index = write_report(
        open_store(db),
        name,
        out,
        paper_dir=paper,
        n_cycles=cycles,
        pairs=pairs,
        design=design,
        n_boot=boots,
    )
    if json_:
        console.print_json(report_document(index))
    else:
        console.out.print(f"wrote {index}")


@command(flags={"n_boot": "--boots"})
def findings(
    name: CampaignArgument,
    boots: Annotated[int, option("Bootstrap replicates of the intervals.")] = 400,
    boot: BootAlias = None,
    seed: Annotated[int, option("Seed of the bootstrap replicates.")] = 0,
    db: DbOption = None,
    json_: JsonOption = False,
    csv: CsvOption = False,
    table: Annotated[
        str | None,
        option(
            "With --csv: findings (the default) | passive (what the passive shape adds) "
            "| momentum (what the velocity history adds).",
            show_default=False,
        ),
    ] = None,
) -> None:
    """The paper's findings F1-F10 measured on a campaign: statistic, value, 95 % bootstrap
    interval, holds / unclear / fails / not measurable (definitions: the documentation's
    explanation/findings page).

    Examples:
      suds-exp findings first --boots 100 --json
      suds-exp findings first --boots 100 --csv --table passive
    """
    from suds_exp.commands.findings import findings_frame, show_findings

    n_boot = either(boots, boot)
    if csv:
        frame = findings_frame(open_store(db), name, table or "findings", n_boot=n_boot, seed=seed)
        console.print_csv(frame)
        return
    show_findings(open_store(db), name, n_boot=n_boot, seed=seed, as_json=json_)


@command(flags={"exclude": "--exclude-candidates", "model_effects": "--effect"})
def discrepancy(
    config: SimConfigOption = None,
    effect: EffectOption = None,
    model: Annotated[Path | None, old_name("--model", "--config")] = None,
    model_effect: Annotated[list[str] | None, old_name("--model-effect", "--effect")] = None,
    trials: TrialsOption = None,
    prep: PrepOption = None,
    alpha: Annotated[float, option("Level of the test naming an effect.")] = 0.01,
    max_effects: Annotated[int, option("Stop after naming this many.")] = 3,
    seed: Annotated[int, option("Seed of the trial split and bootstraps.")] = 0,
    name: Annotated[str | None, option("Run name (default: discrepancy-<time>).")] = None,
    out: Annotated[
        Path | None, option("Report folder (default: reports/discrepancy-NAME).")
    ] = None,
    exclude_candidates: Annotated[
        str | None,
        option("Comma list of effects never offered as candidates."),
    ] = None,
    discover: Annotated[
        bool,
        option(
            "Fit a sparse learned correction when no candidate explains a systematic gap.",
            "--discover/--no-discover",
        ),
    ] = True,
    max_terms: Annotated[int, option("Most terms per channel of that correction.")] = 4,
    db: DbOption = None,
    json_: JsonOption = False,
    quiet: QuietOption = False,
) -> None:
    """Replay the trials through the simulator, find where they disagree, name the missing
    effects (fitted on half the trials, tested on the other half) and report the gap.

    The starting model is --config with --effect applied.

    Examples:
      suds-exp discrepancy --effect flippers=absent --max-effects 1
    """
    from suds_exp.commands.discrepancy import (
        discrepancy_command,
        discrepancy_options,
        print_discrepancy,
        start_model,
    )

    start = start_model(either(config, model), either(effect, model_effect) or [])
    # options are checked before the database is opened
    options = discrepancy_options(alpha, max_effects, seed, exclude_candidates, discover, max_terms)
    result = discrepancy_command(
        open_store(db), start, options, trials, prep, name, out, progress=not (quiet or json_)
    )
    if json_:
        console.print_json(result.to_dict())
    else:
        print_discrepancy(result)


@command()
def demo(
    db: DbOption = None,
    out: Annotated[Path, option("Folder for the campaign report.")] = Path("reports"),
    jobs: JobsOption = 2,
    quiet: QuietOption = False,
    json_: JsonOption = False,
) -> None:
    """Run the whole pipeline on the built-in simulated robot (a few minutes).

    Simulates the paper's design into a temporary folder, ingests it, preprocesses it,
    runs a small campaign with all five learners and writes its report.

    Examples:
      suds-exp demo --db demo.duckdb --out reports -j 2
    """
    from suds_exp.console import output_lines
    from suds_exp.workflows.demo import run_demo

    summary = run_demo(
        open_store(db), out, jobs=jobs, progress=not (quiet or json_), say=output_lines(not json_)
    )
    if json_:
        console.print_json(summary.__dict__)
    else:
        console.out.print(
            f"open {summary.report} and {summary.discrepancy_report} in a browser "
            "to see the results"
        )


# -- stream (online learners on a changing robot) ------------------------------------------
@command(flags={"warmup_cycles": "--warmup"})
def stream(
    name: Annotated[str, typer.Argument(help="Stream name (created, or continued).")],
    models: Annotated[
        str,
        option("Learners, comma-separated; online ones keep learning.", metavar="LEARNERS"),
    ] = "GMR,OnlineGMR",
    trials_: TrialsOption = None,
    prep: PrepOption = None,
    warmup: Annotated[int, option("Cycles that train before scoring starts.")] = 10,
    change_at: Annotated[
        str | None,
        option("Change time (s) of every trial (default: the simulator's schedule)."),
    ] = None,
    plot: Annotated[Path | None, option("Write the error-against-time figure here (PNG).")] = None,
    db: DbOption = None,
    json_: JsonOption = False,
    quiet: QuietOption = False,
) -> None:
    """Prequential evaluation: per trial in time order, predict each cycle, score it, then
    learn it; report recovery after the change and Page-Hinkley drift alarms.

    Rows go to table stream_cycles; a killed stream continues where it stopped. A robot
    that changes: simulate --effect medium_compaction=on@20s, then stream its trials.

    Examples:
      suds-exp stream s --models GMR,OnlineGMR --warmup 2 --plot reports/s.png
    """
    from suds_exp.commands.stream import print_stream, stream_command

    summary = stream_command(
        open_store(db),
        name,
        models,
        trials_,
        prep,
        warmup,
        change_at,
        plot,
        progress=not (quiet or json_),
    )
    if json_:
        console.print_json(summary)
    else:
        print_stream(summary)


gait_app = sub_app(
    "Gaits: predict a gait's motion, draw the learned connection, design and verify."
)
app.add_typer(gait_app, name="gait")


@command(
    on=gait_app,
    name="predict",
    flags={"frequency_hz": "--freqs", "n_boot": "--boots", "learner": "--model"},
)
def gait_predict(
    gait_file: Annotated[
        Path,
        option("CSV phase_rad,<joint>_rad,... or TOML; one column per actuated joint."),
    ],
    freqs: FreqOption = "1/2",
    freq: FreqAlias = None,
    prep: PrepOption = None,
    model: ModelOption = "GMR",
    learner: LearnerAlias = None,
    trials_: TrialsOption = None,
    boots: Annotated[int, option("Bootstrap refits for the 95 % intervals: 0 (none) or 40+.")] = 40,
    boot: BootAlias = None,
    bound: Annotated[float, option("Joint bound the gait must keep, rad.")] = 2.0,
    db: DbOption = None,
    json_: JsonOption = False,
) -> None:
    """Predict a gait's net motion per cycle (forward_mm, lateral_mm, turn_rad, mean_vx_mm_s)
    from a learner fitted on the version's trials, by the SE(2) path-ordered integral;
    warns when the gait leaves the data's support.

    --boots 40 or more gives 95 % intervals.

    Examples:
      suds-exp gait predict --gait-file ellipse.toml --freqs 1/2 --model GMR --boots 0 --json
    """
    from suds_exp.commands.gait import predict_command, predict_text
    from suds_exp.commands.simulate import parse_freq
    from suds_exp.robot import parse_ids

    model = either(model, learner)
    doc = predict_command(
        open_store(db),
        gait_file,
        parse_freq(either(freqs, freq)),
        prep,
        model,
        parse_ids(trials_),
        either(boots, boot),
        bound,
    )
    if json_:
        console.print_json(doc)
    else:
        console.out.print(predict_text(doc, model))


@command(on=gait_app, name="design", flags={"frequency_hz": "--freqs", "learner": "--model"})
def gait_design(
    bound: Annotated[float, option("Joint bound |angle| <= RAD, every joint.")] = 1.3,
    iterations: Annotated[int, option("Design iterations.")] = 5,
    verify: Annotated[
        bool, option("Run each design on the simulator and learn it.", "--verify")
    ] = False,
    prep: PrepOption = None,
    model: ModelOption = "GMR",
    learner: LearnerAlias = None,
    freqs: FreqOption = "1/2",
    freq: FreqAlias = None,
    order: Annotated[int, option("Fourier harmonics per joint.")] = 2,
    out: Annotated[Path, option("Folder for verify trials, designed gaits and the report.")] = Path(
        "reports/gait-design"
    ),
    config: SimConfigOption = None,
    db: DbOption = None,
    json_: JsonOption = False,
) -> None:
    """Design a gait for forward displacement per cycle inside the bound and the trust
    region of the learned map; with --verify, the data-driven loop on the simulator.

    Every iteration is stored (table gait_design_iterations).
    The designed gaits are Fourier TOML files under --out.

    Examples:
      suds-exp gait design --bound 1.3 --iterations 2 --json
      suds-exp gait design --bound 1.3 --iterations 1 --verify
    """
    from suds_exp.commands.gait import design_command, iteration_text
    from suds_exp.commands.simulate import build_config, parse_freq
    from suds_exp.gait.design import DesignOptions

    options = DesignOptions(
        learner=either(model, learner),
        bound=bound,
        iterations=iterations,
        verify=verify,
        frequency_hz=parse_freq(either(freqs, freq)),
        order=order,
    )

    say = None if json_ else (lambda it: console.out.print(iteration_text(it)))
    doc = design_command(
        open_store(db), prep, options, out, build_config(config, []) if config else None, say
    )
    if json_:
        console.print_json(doc)
    else:
        console.out.print(f"design {doc['design_id']} stored; report {doc['report']}")


@command(on=gait_app, name="connection", flags={"half_range": "--range", "learner": "--model"})
def gait_connection(
    out: Annotated[Path, option("CSV file; the figure goes beside it (.png).")] = Path(
        "reports/gait-connection/learned.csv"
    ),
    prep: PrepOption = None,
    model: ModelOption = "GMR",
    learner: LearnerAlias = None,
    grid: GridOption = 21,
    range_: RangeOption = 2.0,
    compare: Annotated[
        bool, option("Beside the simulator's connection (locked).", "--compare")
    ] = False,
    gait_file: Annotated[list[Path] | None, option("Gait files to overlay; repeatable.")] = None,
    directions: Annotated[
        str,
        option(
            "visited: fit from the shape velocities the data took near each shape; "
            "uniform: from 16 evenly spaced ones."
        ),
    ] = "visited",
    config: SimConfigOption = None,
    db: DbOption = None,
    json_: JsonOption = False,
) -> None:
    """The learned local connection, its curl (height function) and support, drawn as
    sysplotter does; --compare adds the simulator's own and their normalised difference.

    --gait-file overlays gaits on the figure.

    Examples:
      suds-exp gait connection --out reports/learned.csv --grid 11 --compare \\
        --gait-file ellipse.toml
    """
    from suds_exp.commands.gait import connection_command, connection_lines
    from suds_exp.commands.simulate import build_config

    summary = connection_command(
        open_store(db),
        out,
        prep,
        either(model, learner),
        grid,
        range_,
        compare,
        build_config(config, []) if config else None,
        gait_file or [],
        directions,
    )
    if json_:
        console.print_json(summary)
        return
    for line in connection_lines(summary):
        console.out.print(line)


plan_app = sub_app(
    "Plan the next recording: which trial teaches the map most or improves the best "
    "gait, and when more data stops helping; the closed loop on the simulator."
)
app.add_typer(plan_app, name="plan")
GoalOption = Annotated[
    str, option("map: learn the map over the target; gait: the best gait in the bound.")
]


@command(
    on=plan_app,
    name="next",
    flags={
        "frequencies_hz": "--freqs",
        "gait_files": "--target",
        "n_boot": "--boots",
        "learner": "--model",
    },
)
def plan_next_cmd(
    goal: GoalOption = "map",
    target: TargetOption = None,
    freqs: TargetFreqsOption = None,
    bound: Annotated[float, option("Joint bound of a designed gait, rad.")] = 1.3,
    n: Annotated[int, option("Trials to recommend (map goal).")] = 1,
    cycles: Annotated[int, option("Cycles per recommended trial.")] = 5,
    prep: PrepOption = None,
    model: ModelOption = "GMR",
    learner: LearnerAlias = None,
    out: Annotated[Path, option("Folder for a new gait's file.")] = Path("plan-next"),
    seed: Annotated[int, option("Seed of the bootstrap refits.")] = 0,
    boots: Annotated[int, option("Bootstrap refits for the uncertainty.")] = 6,
    db: DbOption = None,
    json_: JsonOption = False,
) -> None:
    """Recommend the next trial(s) to record, each with its reason (expected reduction of
    the target's prediction variance, or expected improvement of the best gait), and say
    whether more data of this kind still helps (the learning curve).

    The map goal takes --target gait files and --freqs.

    Examples:
      suds-exp plan next --goal gait --bound 1.3 --json
      suds-exp plan next --goal map --target ellipse.toml --freqs 1/2 --n 2
    """
    from suds_exp.commands.plan import next_command, next_lines

    doc = next_command(
        open_store(db),
        prep,
        goal,
        target or [],
        freqs,
        bound,
        n,
        cycles,
        out,
        either(model, learner),
        seed,
        boots,
    )
    if json_:
        console.print_json(doc)
        return
    for line in next_lines(doc):
        console.out.print(line, markup=False, highlight=False)


@command(
    on=plan_app,
    name="loop",
    flags={"frequencies_hz": "--freqs", "target_files": "--target", "learner": "--model"},
)
def plan_loop_cmd(
    goal: GoalOption = "gait",
    bound: Annotated[float, option("Joint bound |phi1|, |phi2| <= RAD.")] = 1.3,
    budget_cycles: Annotated[int, option("Cycles the loop may record, its warm-up included.")] = 50,
    seed: Annotated[int, option("Seed of the loop (trials and refits).")] = 0,
    cycles: Annotated[int, option("Cycles per planned trial.")] = 5,
    target: TargetOption = None,
    freqs: TargetFreqsOption = None,
    prep: PrepOption = None,
    model: ModelOption = "GMR",
    learner: LearnerAlias = None,
    out: Annotated[Path, option("Folder for the loop's captures and gaits.")] = Path("plan-loop"),
    config: SimConfigOption = None,
    db: DbOption = None,
    json_: JsonOption = False,
    quiet: QuietOption = False,
) -> None:
    """The closed loop with the simulator as the robot: plan a trial, record it, ingest and
    preprocess it into the version, refit; every iteration stored (table plan_iterations).
    Starts from 5 cycles of O at 1/2 Hz when there is no version; run again to continue.

    Examples:
      suds-exp plan loop --goal gait --bound 1.3 --budget-cycles 10 --seed 1 --json
    """
    from suds_exp.commands.plan import iteration_line, loop_command, loop_lines, loop_options
    from suds_exp.commands.simulate import build_config

    recipe = dict(goal=goal, bound=bound, budget_cycles=budget_cycles, seed=seed, cycles=cycles)
    options = loop_options(target, freqs, learner=either(model, learner), **recipe)
    say = None if (json_ or quiet) else (lambda it: console.out.print(iteration_line(it)))
    doc = loop_command(
        open_store(db),
        options,
        prep,
        out,
        build_config(config, []) if config else None,
        progress=not (quiet or json_),
        say=say,
    )
    if json_:
        console.print_json(doc)
        return
    for line in loop_lines(doc):
        console.out.print(line, markup=False, highlight=False)


if __name__ == "__main__":
    app()
