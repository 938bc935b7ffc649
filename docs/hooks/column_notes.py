"""What a column means, where its migration does not say it beside the column.

The database reference (``<!-- generated: database -->``) lists every table, view and
column from a freshly migrated database; this adds a meaning to the columns named here.
A note for a column that no longer exists stops the build, so notes cannot outlive it.
"""

#: table -> column -> its meaning
NOTES: dict[str, dict[str, str]] = {
    "schema_migrations": {
        "version": "migration number",
        "name": "file name without `.sql`",
        "checksum": "SHA-256 of the file's text when applied (a migration edited after it was "
        "applied is refused)",
        "applied_at": "when (UTC)",
    },
    "trials": {
        "id": "trial id (sequence)",
        "source_file": "absolute path of the file when ingested",
        "content_hash": "SHA-256 of the file's bytes (unique: the same file is never stored twice)",
        "format": "reader that read it, e.g. `qtm-tsv`, `c3d`, `csv`",
        "gait": "`S+`, `S-`, `O`, `D-`, `D+`, or NULL when no manifest row named the file",
        "frequency_hz": "gait frequency, Hz (NULL without a condition)",
        "repeat": "repeat number within the condition",
        "sample_rate_hz": "capture rate, Hz",
        "n_frames": "number of frames",
        "marker_names": "the capture's marker names, in file order",
        "layout": "JSON role -> marker name from `--layout`; NULL = the markers carry the role "
        "names",
        "ingested_at": "when the trial was stored",
        "notes": "the manifest's notes",
    },
    "markers": {
        "trial_id": "`trials.id`",
        "frame": "frame number as in the file",
        "t": "time, s",
        "marker": "the capture's marker name",
        "x": "position, mm, in the capture system's frame (NULL when missing)",
        "y": "position, mm",
        "z": "position, mm",
        "missing": "true when the marker was not seen in that frame",
    },
    # preprocessing
    "prep_versions": {
        "params": "the full parameter set (defaults filled in), canonical JSON",
        "params_hash": "SHA-256 of `params`: the same parameters are the same version",
        "k": "passive components kept as r_p",
    },
    "prep_fits": {
        "kind": "`joints`, `pca` or `reducer` (grp '') or `phaser` (grp = the trial group)",
    },
    "prep_pca": {
        "explained_variance": "mm^2",
        "loadings": "12 numbers: head_spoke x/y, tail_spoke x/y, flipper_1..4 x/y",
    },
    "prep_trials": {
        "middle_length_mm": "this trial's mean distance of the segment origins (a trial whose "
        "markers moved stands out)",
        "joint_rms_mm": "RMS deviation of that distance",
    },
    "samples": {
        "t": "time, s",
        "phase": "gait phase, rad, unwrapped",
        "cycle": "floor(phase / 2 pi)",
        "ra_1": "actuated shape: phi1, rad (or head x, mm, with `ra_repr=cartesian`)",
        "ra_2": "phi2, rad (or head y, mm)",
        "dra_1": "d ra_1 / dt (rad/s or mm/s)",
        "rp_1": "passive shape, first component, mm (NULL above the version's k)",
        "drp_1": "its rate, mm/s",
        "vx": "body velocity along the body's X (tail -> head), mm/s, body frame",
        "vy": "lateral body velocity, mm/s, body frame",
        "wz": "yaw rate, rad/s",
    },
    # campaigns
    "campaigns": {
        "prep_version": "name of the preprocessing version its samples come from",
        "definition": "JSON: options (prep, every learner's `get_params()`, boots, train_cycles, "
        "sweep, conditions, mode), test_cycles, samples_per_cycle, decimation, trials used; a "
        "continuation must match it",
    },
    "campaign_runs": {
        "backend": "`in-process`, `loky` or `dask`",
        "n_pending": "jobs left when the run started",
    },
    "results": {
        "train_frequency_hz": "Hz rounded to 6 decimals (1/3 -> 0.333333)",
        "boot": "draw index, 0 .. boots-1",
        "n_cycles": "training cycles",
        "train_trials": "JSON list of the trial ids trained on, in draw order",
        "train_ranges": "JSON list of `[trial id, first cycle, last cycle]`",
        "test_range": "JSON `[first cycle, last cycle]` of the test trial",
        "rmse_vx": "RMS prediction error of vx over the test range, mm/s (NULL if the job failed)",
        "rmse_vy": "mm/s",
        "rmse_wz": "rad/s",
        "n_test": "test samples (after decimation)",
        "fit_seconds": "learner time, s",
        "error": "NULL, or why the job failed",
    },
    # views
    "results_labelled": {
        "gait_steps": "steps between train and test gait on the axis S+, S-, O, D-, D+",
        "gait_sim": "`same` (0 steps), `near` (1), `far` (more)",
        "period_rel": "`<`, `=`, `>`: model period (1 / train frequency) against data period "
        "(1 / test frequency)",
        "ln_rmse_vx": "NULL unless rmse_vx > 0",
    },
    "results_iqr": {
        "pairs": "`same-condition` or `same-frequency`",
        "iqr": "q3 - q1 of rmse_vx, mm/s",
    },
}

COLUMN_NOTES: dict[tuple[str, str], str] = {
    (table, column): note for table, notes in NOTES.items() for column, note in notes.items()
}
