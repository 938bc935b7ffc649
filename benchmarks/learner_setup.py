"""What the learner benchmarks share: the learner settings and the swimmer they learn.

Learner settings are (registry name, parameters) pairs. `benchmarks/models.py` times the
paper's learners and the survey's baselines; `benchmarks/learner_outputs.py` records the
predictions of those and of GMR's variants. Run the benchmarks as scripts from the
repository root (this folder is then on the path).
"""

from suds_exp.testing.synthetic_swimmer import make_samples

#: The paper's learners in both prediction modes of the SUDS variants.
PAPER = [
    ("phase-only", {}),
    ("TLS", {}),
    ("TLS+SUDS", {}),
    ("TLS+SUDS", {"mode": "rollout"}),
    ("GMR", {}),
    ("GMR+SUDS", {}),
    ("GMR+SUDS", {"mode": "rollout"}),
]

#: GMR's augmentation, branching and K-selection variants.
GMR_VARIANTS = [
    ("GMR", {"augment": "dilation"}),
    ("GMR", {"augment": "none", "branching": "filter"}),
    ("GMR+SUDS", {"branching": "history"}),
    ("GMR+SUDS", {"branching": "filter", "mode": "rollout"}),
    ("GMR", {"select_k": "bic", "k_candidates": (4, 8)}),
]

#: The survey's scikit-learn baselines (suds_exp/models/baselines.py).
SURVEY = [
    ("MLP", {"random_state": 0}),
    ("MLP+SUDS", {"random_state": 0}),
    ("MLP+SUDS", {"random_state": 0, "mode": "rollout"}),
    ("GBT", {"random_state": 0}),
    ("kNN", {}),
    ("KRR", {"random_state": 0}),
]


def swimmer_samples(n_cycles: int, gait: str, frequency_hz: float, seed: int, trial_id: int):
    """One trial of the closed-form rate-independent swimmer (passive="travel",
    velocity="finsler") with noise on r_p and dr_p/dt: the samples frame of
    `suds_exp.testing.synthetic_swimmer.make_samples`, trial id `trial_id`."""
    return make_samples(
        n_cycles,
        gait=gait,
        frequency_hz=frequency_hz,
        passive="travel",
        velocity="finsler",
        noise_r=0.005,
        noise_dr=0.05,
        seed=seed,
        first_trial_id=trial_id,
    )
