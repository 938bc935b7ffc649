"""`suds-exp`: the command-line face of the suds_exp library.

Each command parses options and calls one library function; the work lives in
`suds_exp`. User errors (`SudsError`) print one line and exit with status 2.
"""

from __future__ import annotations

import functools
from pathlib import Path
from typing import TYPE_CHECKING, Annotated

import typer

from suds_exp import __version__, console
from suds_exp.commands.messages import user_message
from suds_exp.errors import SudsError

if TYPE_CHECKING:
    from suds_exp.store import Store

app = typer.Typer(
    name="suds-exp",
    help="Learn the motility map of an under-actuated robot from motion capture, "
    "and run the paper's bootstrap experiment on it.",
    no_args_is_help=True,
    add_completion=False,
    pretty_exceptions_enable=False,
)

DbOption = Annotated[
    Path | None,
    typer.Option(
        "--db", envvar="SUDS_DB", help="DuckDB file (default: ./suds.duckdb, or $SUDS_DB)."
    ),
]
JsonOption = Annotated[bool, typer.Option("--json", help="Print one JSON document on stdout.")]


def old_name(flag: str, new: str):
    """A hidden option: ``flag``, the name ``new`` had before the commands shared one
    vocabulary (kept for one release; the changelog lists them)."""
    return typer.Option(flag, hidden=True, help=f"Old name of {new}.")


def either(value, old):
    """The value given under the old name when there was one, else the new name's."""
    return value if old is None else old


QuietOption = Annotated[bool, typer.Option("--quiet", "-q", help="No progress bar.")]


def command(*args, flags: dict[str, str] | None = None, on: typer.Typer | None = None, **kwargs):
    """`app.command` (or ``on``'s, a sub-app) that turns a `SudsError` into one line on
    stderr and its exit code (2; 3 for a lost cluster); ``flags`` maps this command's
    library parameters to flags where `flag` would not."""

    def wrap(fn):
        @functools.wraps(fn)
        def run(*a, **kw):
            try:
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

        return (on or app).command(*args, **kwargs)(run)

    return wrap


def _print_version(value: bool) -> None:
    if value:
        console.out.print(f"suds-exp {__version__}")
        raise typer.Exit()


@app.callback()
def main(
    version: Annotated[
        bool,
        typer.Option(
            "--version", callback=_print_version, is_eager=True, help="Print the version and exit."
        ),
    ] = False,
) -> None:
    # the options of `suds-exp` itself, before any command; the help text is the app's
    pass


def open_store(db: Path | None) -> Store:
    # imported here: `--version` and `--help` need neither SQLAlchemy nor pandas
    from suds_exp.store import Store, default_db_path

    return Store(db if db is not None else default_db_path())


@command()
def init(db: DbOption = None) -> None:
    """Create the database, or upgrade it to the latest schema."""
    store = open_store(db)
    applied = store.upgrade()
    console.out.print(
        f"{store.path}: " + (f"applied {', '.join(applied)}" if applied else "up to date")
    )


@command()
def ingest(
    paths: Annotated[list[Path] | None, typer.Argument(help="Capture files or folders.")] = None,
    manifest: Annotated[
        Path | None, typer.Option(help="CSV file,gait,frequency_hz,repeat,notes.")
    ] = None,
    layout: Annotated[Path | None, typer.Option(help="CSV role,marker for the 11 roles.")] = None,
    software: Annotated[
        str | None,
        typer.Option(
            help="Keypoint files' tracker: deeplabcut, sleap, lightning-pose, anipose "
            "(default: told by the file)."
        ),
    ] = None,
    fps: Annotated[
        float | None, typer.Option(help="Keypoint files' frame rate, when the file lacks it.")
    ] = None,
    mm_per_px: Annotated[
        float | None, typer.Option(help="Scale of 2-D keypoints, mm per pixel.")
    ] = None,
    confidence_threshold: Annotated[
        float | None,
        typer.Option(help="Keypoints below this confidence are missing (default 0.6)."),
    ] = None,
    experiment: Annotated[
        Path | None, typer.Option(help="TOML of the condition axes (default: the paper's).")
    ] = None,
    db: DbOption = None,
    json_: JsonOption = False,
    quiet: QuietOption = False,
) -> None:
    """Ingest QTM TSV, C3D, Vicon Nexus / Motive / marker CSV and TRC files, and keypoint
    files of DeepLabCut, SLEAP, Lightning Pose and Anipose (needs suds-exp\\[pose]).

    Each file is one transaction; a bad file is reported in one line and the others are
    still stored (exit status 2 at the end). Example: suds-exp ingest data/ --manifest
    data/manifest.csv; suds-exp ingest mouse.h5 --fps 30 --mm-per-px 0.1
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
def trials(db: DbOption = None, json_: JsonOption = False) -> None:
    """List the trials and their conditions."""
    from suds_exp.commands.ingest import print_trials
    from suds_exp.ingest import list_trials

    print_trials(list_trials(open_store(db)), json_)


@command()
def sql(
    query: Annotated[str, typer.Argument(help="SQL to run on a read-only connection.")],
    db: DbOption = None,
    json_: JsonOption = False,
) -> None:
    """Run a read-only SQL query and print the result; statements that write are refused.

    Example: suds-exp sql "SELECT gait, count(*) FROM trials GROUP BY gait"
    """
    from suds_exp.store import run_readonly

    frame = run_readonly(open_store(db), query)
    if json_:
        console.print_json(frame)
    else:
        console.print_frame(frame)


EffectOption = Annotated[
    list[str] | None,
    typer.Option(
        "--effect",
        help="NAME=VALUE (or NAME.PARAM=VALUE, on, off); repeatable. "
        "simulate also takes a schedule NAME=VALUE@TIMEs, e.g. flippers=locked@40s.",
    ),
]
SimConfigOption = Annotated[
    Path | None, typer.Option("--config", help="Simulator config (.toml or .json).")
]


@command(flags={"frequencies_hz": "--freqs"})
def simulate(
    out: Annotated[Path, typer.Option(help="Folder for TSV, truth Parquet and manifest.")],
    config: SimConfigOption = None,
    gaits: Annotated[
        str | None, typer.Option(help="Comma list, e.g. S+,O (default: all five).")
    ] = None,
    freqs: Annotated[str | None, typer.Option(help="Hz, comma list (default: 1/3,1/2,1).")] = None,
    repeats: Annotated[int, typer.Option(help="Trials per condition.")] = 4,
    cycles: Annotated[
        str | None, typer.Option(help="Cycles per trial MIN:MAX (default: 10:30).")
    ] = None,
    seed: Annotated[int, typer.Option(help="Same seed, same files.")] = 0,
    effect: EffectOption = None,
    ingest: Annotated[bool, typer.Option("--ingest", help="Ingest the result into --db.")] = False,
    gait_file: Annotated[
        Path | None,
        typer.Option(help="A gait file (CSV phase_rad,phi1_rad,phi2_rad or Fourier TOML)."),
    ] = None,
    db: DbOption = None,
    json_: JsonOption = False,
    quiet: QuietOption = False,
) -> None:
    """Simulate the swimmer and write QTM TSV captures, truth Parquet files and a manifest.

    Example: suds-exp simulate --out sim-data --gaits O,D+ --repeats 2 --effect hinge_damping=on;
    suds-exp simulate --out ell --gait-file ellipse.toml --freqs 1/2 --ingest
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
    out: Annotated[Path, typer.Option(help="CSV file; figures go beside it (_vx/_vy/_wz.png).")],
    grid: Annotated[int, typer.Option(help="Points per joint axis.")] = 21,
    range_: Annotated[float, typer.Option("--range", help="Half range of phi1, phi2 (rad).")] = 2.5,
    geometry: Annotated[str, typer.Option(help="robot or classic (3 equal links).")] = "robot",
    config: SimConfigOption = None,
    effect: EffectOption = None,
    json_: JsonOption = False,
) -> None:
    """Local connection with flippers locked: body velocity per unit joint rate on a grid.

    Example: suds-exp connection --out reports/connection.csv --geometry classic
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
) -> None:
    """List the simulator's named effects: parameters, units, nominal values, ranges.

    Example: suds-exp effects --json
    """
    from suds_exp.commands.simulate import build_config, effects_table
    from suds_exp.sim import effect_library

    if json_:
        console.print_json(effect_library(build_config(config, effect or [])))
    else:
        console.print_frame(
            effects_table(build_config(config, effect or [])), title="effects (* = main)"
        )


@command()
def preprocess(
    name: Annotated[
        str | None, typer.Option(help="Name of a new version (default: v<id>).")
    ] = None,
    param: Annotated[
        list[str] | None, typer.Option("--param", help="KEY=VALUE over the defaults; repeatable.")
    ] = None,
    trials_: Annotated[
        str | None, typer.Option("--trials", help="Trial ids, e.g. 1,2,5-8 (default: all).")
    ] = None,
    list_: Annotated[bool, typer.Option("--list", help="List the versions and exit.")] = False,
    body: Annotated[
        str | None,
        typer.Option(help="Body description: a TOML file, or 'swimmer' (the default body)."),
    ] = None,
    preset: Annotated[
        str | None,
        typer.Option(help="Named parameter set under --param: default | paper (the paper's own)."),
    ] = None,
    db: DbOption = None,
    json_: JsonOption = False,
    quiet: QuietOption = False,
) -> None:
    """Turn markers into samples (shape, phase, body velocity) as a stored version.

    The same parameters are the same version: re-running skips the trials already done.
    Example: suds-exp preprocess --name smooth --param sg_window_cycles=0.15 --trials 1-20;
    suds-exp preprocess --body snake.toml (a marker chain: shape modes of chord angles)
    suds-exp preprocess --preset paper --name paper (the paper's own processing)
    """
    from suds_exp.commands.preprocess import preprocess_command, preprocess_text, print_versions

    store = open_store(db)
    if list_:
        print_versions(store, json_)
        return
    result = preprocess_command(
        store, name, param or [], trials_, body, preset, progress=not (quiet or json_)
    )
    if json_:
        console.print_json(result.to_dict())
    else:
        console.out.print(preprocess_text(result))


CampaignModelsOption = Annotated[
    str | None,
    typer.Option(
        help="Learners, comma-separated (default: the paper's five); MLP, GBT, kNN, KRR "
        "(+SUDS), sklearn:ClassName[+SUDS]; survey = the five and the baselines."
    ),
]
ModelParamOption = Annotated[
    list[str] | None,
    typer.Option(help="NAME.KEY=VALUE for a learner of --models, e.g. MLP.alpha=0.01."),
]
SkipInfeasibleOption = Annotated[
    bool | None,
    typer.Option(
        "--skip-infeasible/--no-skip-infeasible",
        help="Leave out the (condition, training size) cells the data cannot supply "
        "instead of refusing the campaign; stored in its definition.",
    ),
]


@command()
def run(
    name: Annotated[str, typer.Argument(help="Campaign name (created, or continued).")],
    prep: Annotated[str | None, typer.Option(help="Preprocessing version of the samples.")] = None,
    models: CampaignModelsOption = None,
    boots: Annotated[
        int | None, typer.Option(help="Draws per (train, test) pair (default 10).")
    ] = None,
    train_cycles: Annotated[
        int | None, typer.Option(help="Training (and test) cycles of the main grid (default 30).")
    ] = None,
    sweep: Annotated[
        str | None,
        typer.Option(help="Sample-efficiency sweep on same-condition pairs: 1-10,21,48 or paper."),
    ] = None,
    train_conditions: Annotated[
        str | None, typer.Option(help="GAIT@FREQ, GAIT or @FREQ, comma-separated (default: all).")
    ] = None,
    test_conditions: Annotated[str | None, typer.Option(help="As --train-conditions.")] = None,
    mode: Annotated[
        str | None, typer.Option(help="SUDS learners: measured or rollout (default measured).")
    ] = None,
    model_param: ModelParamOption = None,
    skip_infeasible: SkipInfeasibleOption = None,
    jobs: Annotated[int, typer.Option("--jobs", "-j", help="Workers (-1: all cores).")] = 1,
    backend: Annotated[str, typer.Option(help="loky (this machine) or dask.")] = "loky",
    scheduler: Annotated[
        str | None, typer.Option(help="dask scheduler address, e.g. tcp://host:8786.")
    ] = None,
    db: DbOption = None,
    json_: JsonOption = False,
    quiet: QuietOption = False,
) -> None:
    """Create or continue a bootstrap campaign; Ctrl-C stops after saving finished jobs.

    An option left out of a continued campaign takes its stored value; a different value
    is refused. Example: suds-exp run paper --prep default --sweep paper --jobs 2
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
    cycles: Annotated[int, typer.Option(help="Main grid size: GMR's error target.")] = 30,
    versus: Annotated[
        str, typer.Option(help="Learner whose data need is set against GMR's.")
    ] = "MLP",
    boots: Annotated[int, typer.Option(help="Bootstrap resamples of the ratio.")] = 1000,
    n_boot: Annotated[int | None, old_name("--n-boot", "--boots")] = None,
    db: DbOption = None,
    json_: JsonOption = False,
) -> None:
    """Data each learner needs and its speed: cycles to reach x1.25 of its own largest-sweep
    error and GMR's 30-cycle error, per frequency, and the VERSUS/GMR data ratio (from a
    sweep); the GLM with the learner as a factor (from a main grid's cross pairs).

    Example: suds-exp run s --models survey --sweep 1,2,4,8,16,30,48 && suds-exp survey s
    """
    from suds_exp.analysis.survey import survey_json, survey_tables
    from suds_exp.commands.survey import print_survey

    tables = survey_tables(open_store(db), name, cycles, either(boots, n_boot), versus)
    if json_:
        console.print_json(survey_json(tables))
    else:
        print_survey(tables, cycles)


@command()
def status(
    name: Annotated[str, typer.Argument(help="Campaign name.")],
    db: DbOption = None,
    json_: JsonOption = False,
) -> None:
    """Jobs done / total per learner, rate and time left of a campaign (also while it runs)."""
    from suds_exp.campaign import campaign_status
    from suds_exp.commands.campaign import print_status

    report = campaign_status(open_store(db), name)
    if json_:
        console.print_json(report)
    else:
        print_status(report)


@command(flags={"n_cycles": "--cycles", "paper_dir": "--paper", "n_boot": "--boots"})
def report(
    name: Annotated[str, typer.Argument(help="Campaign name.")],
    out: Annotated[Path | None, typer.Option(help="Folder (default: reports/NAME).")] = None,
    cycles: Annotated[
        int | None, typer.Option(help="Training size of box plots and GLMs (default: most common).")
    ] = None,
    pairs: Annotated[
        str, typer.Option(help="Spread/efficiency pairs: same-condition or same-frequency.")
    ] = "same-condition",
    paper: Annotated[
        Path | None, typer.Option(help="Folder of the paper's glm_table.csv and iqr_table.csv.")
    ] = None,
    experiment: Annotated[
        Path | None,
        typer.Option(help="TOML of the condition axes (default: the one stored at ingest)."),
    ] = None,
    boots: Annotated[
        int, typer.Option(help="Bootstrap replicates of the findings' intervals.")
    ] = 400,
    db: DbOption = None,
    json_: JsonOption = False,
) -> None:
    """Write a campaign's report: box plots, GLM, IQR and slope tables, paper comparison.

    Example: suds-exp report paper --out reports/paper   (then open reports/paper/index.html)
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
    name: Annotated[str, typer.Argument(help="Campaign name.")],
    boots: Annotated[int, typer.Option(help="Bootstrap replicates of the intervals.")] = 400,
    boot: Annotated[int | None, old_name("--boot", "--boots")] = None,
    seed: Annotated[int, typer.Option(help="Seed of the bootstrap replicates.")] = 0,
    db: DbOption = None,
    json_: JsonOption = False,
) -> None:
    """The paper's findings F1-F10 measured on a campaign: statistic, value, 95 % bootstrap
    interval, holds / unclear / fails / not measurable (definitions: docs/explanation/findings.md).

    Example: suds-exp findings paper --json
    """
    from suds_exp.commands.findings import show_findings

    show_findings(open_store(db), name, n_boot=either(boots, boot), seed=seed, as_json=json_)


@command(flags={"exclude": "--exclude-candidates", "model_effects": "--model-effect"})
def discrepancy(
    model: Annotated[
        Path | None, typer.Option("--model", help="Starting simulator config (default: nominal).")
    ] = None,
    model_effect: Annotated[
        list[str] | None,
        typer.Option("--model-effect", help="NAME=VALUE on the starting model; repeatable."),
    ] = None,
    trials: Annotated[
        str | None, typer.Option(help="Comma list of trial ids (default: all).")
    ] = None,
    prep: Annotated[
        str | None, typer.Option(help="Preprocessing version (default: the only one).")
    ] = None,
    alpha: Annotated[float, typer.Option(help="Level of the test naming an effect.")] = 0.01,
    max_effects: Annotated[int, typer.Option(help="Stop after naming this many.")] = 3,
    seed: Annotated[int, typer.Option(help="Seed of the trial split and bootstraps.")] = 0,
    name: Annotated[
        str | None, typer.Option(help="Run name (default: discrepancy-<time>).")
    ] = None,
    out: Annotated[
        Path | None, typer.Option(help="Report folder (default: reports/discrepancy-NAME).")
    ] = None,
    exclude_candidates: Annotated[
        str | None,
        typer.Option(help="Comma list of effects never offered as candidates."),
    ] = None,
    discover: Annotated[
        bool,
        typer.Option(
            "--discover/--no-discover",
            help="Fit a sparse learned correction when no candidate explains a systematic gap.",
        ),
    ] = True,
    max_terms: Annotated[int, typer.Option(help="Most terms per channel of that correction.")] = 4,
    db: DbOption = None,
    json_: JsonOption = False,
    quiet: QuietOption = False,
) -> None:
    """Replay the trials through the simulator, find where they disagree, name the missing
    effects (fitted on half the trials, tested on the other half) and report the gap.

    Example: suds-exp discrepancy --model-effect flippers=absent --max-effects 2
    """
    from suds_exp.commands.discrepancy import (
        discrepancy_command,
        discrepancy_options,
        print_discrepancy,
        start_model,
    )

    start = start_model(model, model_effect or [])
    # options are checked before the database is opened
    options = discrepancy_options(alpha, max_effects, seed, exclude_candidates, discover, max_terms)
    result = discrepancy_command(
        open_store(db), start, options, trials, prep, name, out, progress=not (quiet or json_)
    )
    if json_:
        console.print_json(result.to_json())
    else:
        print_discrepancy(result)


@command()
def demo(
    db: DbOption = None,
    out: Annotated[Path, typer.Option(help="Folder for the campaign report.")] = Path("reports"),
    jobs: Annotated[int, typer.Option(help="Worker processes for the campaign.")] = 2,
    quiet: QuietOption = False,
    json_: JsonOption = False,
) -> None:
    """Run the whole pipeline on the built-in simulated robot (a few minutes).

    Simulates the paper's design into a temporary folder, ingests it, preprocesses it,
    runs a small campaign with all five learners and writes its report.
    """
    from suds_exp.testing.demo import run_demo

    summary = run_demo(
        open_store(db), out, jobs=jobs, progress=not (quiet or json_), narrate=not json_
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
        str, typer.Option(help="Learners, comma-separated; online ones keep learning.")
    ] = "GMR,OnlineGMR",
    trials_: Annotated[
        str | None, typer.Option("--trials", help="Trial ids, e.g. 1,2,5-8 (default: all).")
    ] = None,
    prep: Annotated[
        str | None, typer.Option(help="Preprocessing version (default: the only one).")
    ] = None,
    warmup: Annotated[int, typer.Option(help="Cycles that train before scoring starts.")] = 10,
    change_at: Annotated[
        str | None,
        typer.Option(help="Change time (s) of every trial (default: the simulator's schedule)."),
    ] = None,
    plot: Annotated[
        Path | None, typer.Option(help="Write the error-against-time figure here (PNG).")
    ] = None,
    db: DbOption = None,
    json_: JsonOption = False,
    quiet: QuietOption = False,
) -> None:
    """Prequential evaluation: per trial in time order, predict each cycle, score it, then
    learn it; report recovery after the change and Page-Hinkley drift alarms.

    Rows go to table stream_cycles; a killed stream continues where it stopped.
    Example: suds-exp simulate --out bed --gaits O --freqs 1 --repeats 4 --cycles 60
    --effect medium_compaction=on@20s --ingest && suds-exp preprocess && suds-exp stream
    bed --models GMR,OnlineGMR --plot reports/bed.png
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


gait_app = typer.Typer(
    help="Gaits: predict a gait's motion, draw the learned connection, design and verify.",
    no_args_is_help=True,
)
app.add_typer(gait_app, name="gait")
PrepOption = Annotated[
    str | None, typer.Option(help="Preprocessing version (default: the only one).")
]
LearnerOption = Annotated[str, typer.Option(help="Learner name (see suds_exp.models).")]


@command(on=gait_app, name="predict", flags={"frequency_hz": "--freq", "n_boot": "--boots"})
def gait_predict(
    gait_file: Annotated[
        Path,
        typer.Option(help="CSV phase_rad,<joint>_rad,... or TOML; one column per actuated joint."),
    ],
    freq: Annotated[str, typer.Option(help="Gait frequency, Hz (e.g. 1/2).")] = "0.5",
    prep: PrepOption = None,
    learner: LearnerOption = "GMR",
    trials_: Annotated[
        str | None, typer.Option("--trials", help="Training trial ids (default: all).")
    ] = None,
    boots: Annotated[
        int, typer.Option(help="Bootstrap refits for the 95 % intervals: 0 (none) or 40+.")
    ] = 40,
    boot: Annotated[int | None, old_name("--boot", "--boots")] = None,
    bound: Annotated[float, typer.Option(help="Joint bound the gait must keep, rad.")] = 2.0,
    db: DbOption = None,
    json_: JsonOption = False,
) -> None:
    """Predict a gait's net motion per cycle (forward_mm, lateral_mm, turn_rad, mean_vx_mm_s)
    from a learner fitted on the version's trials, by the SE(2) path-ordered integral;
    warns when the gait leaves the data's support.

    Example: suds-exp gait predict --gait-file ellipse.toml --freq 1/2 --learner GMR --json
    """
    from suds_exp.commands.gait import predict_command, predict_text
    from suds_exp.commands.simulate import parse_freqs
    from suds_exp.robot import parse_ids

    (frequency,) = parse_freqs(freq)[:1]
    doc = predict_command(
        open_store(db),
        gait_file,
        frequency,
        prep,
        learner,
        parse_ids(trials_),
        either(boots, boot),
        bound,
    )
    if json_:
        console.print_json(doc)
    else:
        console.out.print(predict_text(doc, learner))


@command(on=gait_app, name="design", flags={"frequency_hz": "--freq"})
def gait_design(
    bound: Annotated[float, typer.Option(help="Joint bound |angle| <= RAD, every joint.")] = 1.3,
    iterations: Annotated[int, typer.Option(help="Design iterations.")] = 5,
    verify: Annotated[
        bool, typer.Option("--verify", help="Run each design on the simulator and learn it.")
    ] = False,
    prep: PrepOption = None,
    learner: LearnerOption = "GMR",
    freq: Annotated[str, typer.Option(help="Gait frequency, Hz.")] = "0.5",
    order: Annotated[int, typer.Option(help="Fourier harmonics per joint.")] = 2,
    out: Annotated[
        Path, typer.Option(help="Folder for verify trials, designed gaits and the report.")
    ] = Path("reports/gait-design"),
    config: SimConfigOption = None,
    db: DbOption = None,
    json_: JsonOption = False,
) -> None:
    """Design a gait for forward displacement per cycle inside the bound and the trust
    region of the learned map; with --verify, the data-driven loop on the simulator.

    Every iteration is stored (table gait_design_iterations).
    Example: suds-exp gait design --bound 1.3 --iterations 5 --verify --json
    """
    from suds_exp.commands.gait import design_command, iteration_text
    from suds_exp.commands.simulate import build_config, parse_freqs
    from suds_exp.gait.design import DesignOptions

    options = DesignOptions(
        learner=learner,
        bound=bound,
        iterations=iterations,
        verify=verify,
        frequency_hz=parse_freqs(freq)[0],
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


@command(on=gait_app, name="connection", flags={"half_range": "--range"})
def gait_connection(
    out: Annotated[Path, typer.Option(help="CSV file; the figure goes beside it (.png).")] = Path(
        "reports/gait-connection/learned.csv"
    ),
    prep: PrepOption = None,
    learner: LearnerOption = "GMR",
    grid: Annotated[int, typer.Option(help="Points per joint axis.")] = 21,
    range_: Annotated[float, typer.Option("--range", help="Half range of phi1, phi2 (rad).")] = 2.0,
    compare: Annotated[
        bool, typer.Option("--compare", help="Beside the simulator's connection (locked).")
    ] = False,
    gait_file: Annotated[
        list[Path] | None, typer.Option(help="Gait files to overlay; repeatable.")
    ] = None,
    directions: Annotated[
        str,
        typer.Option(
            help="visited: fit from the shape velocities the data took near each shape; "
            "uniform: from 16 evenly spaced ones."
        ),
    ] = "visited",
    config: SimConfigOption = None,
    db: DbOption = None,
    json_: JsonOption = False,
) -> None:
    """The learned local connection, its curl (height function) and support, drawn as
    sysplotter does; --compare adds the simulator's own and their normalised difference.

    Example: suds-exp gait connection --out reports/learned.csv --compare
    """
    from suds_exp.commands.gait import connection_command, connection_lines
    from suds_exp.commands.simulate import build_config

    summary = connection_command(
        open_store(db),
        out,
        prep,
        learner,
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


plan_app = typer.Typer(
    help="Plan the next recording: which trial teaches the map most or improves the best "
    "gait, and when more data stops helping; the closed loop on the simulator.",
    no_args_is_help=True,
)
app.add_typer(plan_app, name="plan")
GoalOption = Annotated[
    str, typer.Option(help="map: learn the map over the target; gait: the best gait in the bound.")
]


@command(
    on=plan_app,
    name="next",
    flags={"frequencies_hz": "--freqs", "gait_files": "--target", "n_boot": "--boots"},
)
def plan_next_cmd(
    goal: GoalOption = "map",
    target: Annotated[
        list[Path] | None, typer.Option(help="Target gait file (CSV or TOML); repeatable.")
    ] = None,
    freqs: Annotated[str | None, typer.Option(help="Target frequencies, Hz (default 1/2).")] = None,
    bound: Annotated[float, typer.Option(help="Joint bound of a designed gait, rad.")] = 1.3,
    n: Annotated[int, typer.Option(help="Trials to recommend (map goal).")] = 1,
    cycles: Annotated[int, typer.Option(help="Cycles per recommended trial.")] = 5,
    prep: PrepOption = None,
    learner: LearnerOption = "GMR",
    out: Annotated[Path, typer.Option(help="Folder for a new gait's file.")] = Path("plan-next"),
    seed: Annotated[int, typer.Option(help="Seed of the bootstrap refits.")] = 0,
    boots: Annotated[int, typer.Option(help="Bootstrap refits for the uncertainty.")] = 6,
    db: DbOption = None,
    json_: JsonOption = False,
) -> None:
    """Recommend the next trial(s) to record, each with its reason (expected reduction of
    the target's prediction variance, or expected improvement of the best gait), and say
    whether more data of this kind still helps (the learning curve).

    Example: suds-exp plan next --goal gait --bound 1.3 --json
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
        learner,
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
    flags={"frequencies_hz": "--freqs", "target_files": "--target"},
)
def plan_loop_cmd(
    goal: GoalOption = "gait",
    bound: Annotated[float, typer.Option(help="Joint bound |phi1|, |phi2| <= RAD.")] = 1.3,
    budget_cycles: Annotated[
        int, typer.Option(help="Cycles the loop may record, its warm-up included.")
    ] = 50,
    seed: Annotated[int, typer.Option(help="Seed of the loop (trials and refits).")] = 0,
    cycles: Annotated[int, typer.Option(help="Cycles per planned trial.")] = 5,
    target: Annotated[
        list[Path] | None, typer.Option(help="Target gait file (CSV or TOML); repeatable.")
    ] = None,
    freqs: Annotated[str | None, typer.Option(help="Target frequencies, Hz (default 1/2).")] = None,
    prep: PrepOption = None,
    learner: LearnerOption = "GMR",
    out: Annotated[Path, typer.Option(help="Folder for the loop's captures and gaits.")] = Path(
        "plan-loop"
    ),
    config: SimConfigOption = None,
    db: DbOption = None,
    json_: JsonOption = False,
    quiet: QuietOption = False,
) -> None:
    """The closed loop with the simulator as the robot: plan a trial, record it, ingest and
    preprocess it into the version, refit; every iteration stored (table plan_iterations).
    Starts from 5 cycles of O at 1/2 Hz when there is no version; run again to continue.

    Example: suds-exp plan loop --goal gait --bound 1.3 --budget-cycles 50 --seed 1 --json
    """
    from suds_exp.commands.plan import iteration_line, loop_command, loop_lines, loop_options
    from suds_exp.commands.simulate import build_config

    options = loop_options(goal, bound, budget_cycles, seed, cycles, learner, target, freqs)
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
