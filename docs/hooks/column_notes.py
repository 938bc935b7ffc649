"""What a column means, where its migration does not say it beside the column.

The database reference (``<!-- generated: database -->``) lists every table, view and
column from a freshly migrated database; this adds a meaning to the columns named here.
A note for a column that no longer exists stops the build, so notes cannot outlive it.
"""

COLUMN_NOTES: dict[tuple[str, str], str] = {
    # schema_migrations
    ("schema_migrations", "version"): "migration number",
    ("schema_migrations", "name"): "file name without `.sql`",
    ("schema_migrations", "checksum"): "SHA-256 of the file's text when applied "
    "(a migration edited after it was applied is refused)",
    ("schema_migrations", "applied_at"): "when (UTC)",
    # trials
    ("trials", "id"): "trial id (sequence)",
    ("trials", "source_file"): "absolute path of the file when ingested",
    ("trials", "content_hash"): "SHA-256 of the file's bytes (unique: the same file is "
    "never stored twice)",
    ("trials", "format"): "reader that read it, e.g. `qtm-tsv`, `c3d`, `csv`",
    ("trials", "gait"): "`S+`, `S-`, `O`, `D-`, `D+`, or NULL when no manifest row named the file",
    ("trials", "frequency_hz"): "gait frequency, Hz (NULL without a condition)",
    ("trials", "repeat"): "repeat number within the condition",
    ("trials", "sample_rate_hz"): "capture rate, Hz",
    ("trials", "n_frames"): "number of frames",
    ("trials", "marker_names"): "the capture's marker names, in file order",
    ("trials", "layout"): "JSON role -> marker name from `--layout`; NULL = the markers "
    "carry the role names",
    ("trials", "ingested_at"): "when the trial was stored",
    ("trials", "notes"): "the manifest's notes",
    # markers
    ("markers", "trial_id"): "`trials.id`",
    ("markers", "frame"): "frame number as in the file",
    ("markers", "t"): "time, s",
    ("markers", "marker"): "the capture's marker name",
    ("markers", "x"): "position, mm, in the capture system's frame (NULL when missing)",
    ("markers", "y"): "position, mm",
    ("markers", "z"): "position, mm",
    ("markers", "missing"): "true when the marker was not seen in that frame",
    # preprocessing
    ("prep_versions", "params"): "the full parameter set (defaults filled in), canonical JSON",
    ("prep_versions", "params_hash"): "SHA-256 of `params`: the same parameters are the "
    "same version",
    ("prep_versions", "k"): "passive components kept as r_p",
    ("prep_fits", "kind"): "`joints`, `pca` or `reducer` (grp '') or `phaser` (grp = the "
    "trial group)",
    ("prep_pca", "explained_variance"): "mm^2",
    ("prep_pca", "loadings"): "12 numbers: head_spoke x/y, tail_spoke x/y, flipper_1..4 x/y",
    ("prep_trials", "middle_length_mm"): "this trial's mean distance of the segment "
    "origins (a trial whose markers moved stands out)",
    ("prep_trials", "joint_rms_mm"): "RMS deviation of that distance",
    ("samples", "t"): "time, s",
    ("samples", "phase"): "gait phase, rad, unwrapped",
    ("samples", "cycle"): "floor(phase / 2 pi)",
    ("samples", "ra_1"): "actuated shape: phi1, rad (or head x, mm, with `ra_repr=cartesian`)",
    ("samples", "ra_2"): "phi2, rad (or head y, mm)",
    ("samples", "dra_1"): "d ra_1 / dt (rad/s or mm/s)",
    ("samples", "rp_1"): "passive shape, first component, mm (NULL above the version's k)",
    ("samples", "drp_1"): "its rate, mm/s",
    ("samples", "vx"): "body velocity along the body's X (tail -> head), mm/s, body frame",
    ("samples", "vy"): "lateral body velocity, mm/s, body frame",
    ("samples", "wz"): "yaw rate, rad/s",
    # campaigns
    ("campaigns", "prep_version"): "name of the preprocessing version its samples come from",
    ("campaigns", "definition"): "JSON: options (prep, every learner's `get_params()`, "
    "boots, train_cycles, sweep, conditions, mode), test_cycles, samples_per_cycle, "
    "decimation, trials used; a continuation must match it",
    ("campaign_runs", "backend"): "`in-process`, `loky` or `dask`",
    ("campaign_runs", "n_pending"): "jobs left when the run started",
    ("results", "train_frequency_hz"): "Hz rounded to 6 decimals (1/3 -> 0.333333)",
    ("results", "boot"): "draw index, 0 .. boots-1",
    ("results", "n_cycles"): "training cycles",
    ("results", "train_trials"): "JSON list of the trial ids trained on, in draw order",
    ("results", "train_ranges"): "JSON list of `[trial id, first cycle, last cycle]`",
    ("results", "test_range"): "JSON `[first cycle, last cycle]` of the test trial",
    ("results", "rmse_vx"): "RMS prediction error of vx over the test range, mm/s (NULL if "
    "the job failed)",
    ("results", "rmse_vy"): "mm/s",
    ("results", "rmse_wz"): "rad/s",
    ("results", "n_test"): "test samples (after decimation)",
    ("results", "fit_seconds"): "learner time, s",
    ("results", "error"): "NULL, or why the job failed",
    # views
    ("results_labelled", "gait_steps"): "steps between train and test gait on the axis "
    "S+, S-, O, D-, D+",
    ("results_labelled", "gait_sim"): "`same` (0 steps), `near` (1), `far` (more)",
    ("results_labelled", "period_rel"): "`<`, `=`, `>`: model period (1 / train frequency) "
    "against data period (1 / test frequency)",
    ("results_labelled", "ln_rmse_vx"): "NULL unless rmse_vx > 0",
    ("results_iqr", "pairs"): "`same-condition` or `same-frequency`",
    ("results_iqr", "iqr"): "q3 - q1 of rmse_vx, mm/s",
}
