"""``wheelsoil validate`` and ``wheelsoil predict``: their command-line options and their runs (the validation
workflow itself is :mod:`wheelsoil.validation.workflow`)."""

from __future__ import annotations

from pathlib import Path

from rich.console import Console

from wheelsoil.errors import WheelsoilInputError


def add_parser(sub) -> None:
    """The ``validate`` and ``predict`` subcommands on ``sub`` (argparse subparsers)."""
    p = sub.add_parser("validate", help="hold the semi-empirical model against measured data; name what it misses",
                       description="Calibrate the classical wheel-soil model (Wong-Reece, Janosi-Hanamoto, lateral "
                                   "shear, in velocity components so braking, dragged and 90 deg rows are used; "
                                   "every soil parameter the data can inform free, unidentified and at-bound "
                                   "ones flagged) on training conditions, diagnose its residuals, then select "
                                   "mechanisms forward (slip-sinkage, theta_m moving with slip, soil flow, sidewall, "
                                   "grousers, grouser tips, surrogate radius, gravity acting through cohesion, pressure "
                                   "or soil flow, bulldozing, multipass): each step refits the model with every "
                                   "remaining candidate and accepts the one that lowers BIC by 10, gains on held-out "
                                   "data, has a physical parameter and removes most of the systematic residual; "
                                   "ambiguities and unexplained trends are reported. Writes report.md, findings.json, "
                                   "model.json (for 'wheelsoil predict') and plots to --report. DATA: a folder of CMU trial files, the digitised single-wheel CSV, a "
                                   "CSV in wheelsoil's format (slip, vertical_load_N, wheel_radius_m, "
                                   "wheel_width_m, drawbar_pull_N, ...), a wheelsoil sweep folder (the DEM-FEM "
                                   "runs of 'wheelsoil batch' as data: what the classical model misses of the "
                                   "simulation), 'synthetic' (a hidden mechanism, revealed at the end of the "
                                   "report), or 'synthetic-periodic' (drawbar-pull series with a hidden periodic "
                                   "mechanism: seed 002's density wave or seed 000's spoke-stiffness radius; the "
                                   "frequency law and the amplitude mechanism are named).")
    p.add_argument("data", help="measured data (folder or CSV), a sweep folder, 'synthetic' or 'synthetic-periodic'")
    p.add_argument("--model", nargs="+", default=["semi-empirical"], metavar="MODEL",
                   help="model to hold against the data: 'semi-empirical' (default: the terramechanics model, "
                        "calibrated, with the candidate mechanisms) or one or more wheelsoil sweep folders / "
                        "summary.csv files (the DEM-FEM runs, taken together and compared with the measured data "
                        "condition by condition)")
    p.add_argument("--allow-unpaired-runs", action="store_true",
                   help="with --model: leave out runs that twin no measured condition instead of refusing them")
    p.add_argument("--report", type=Path, default=Path("wheelsoil-output/validation"), help="report folder")
    p.add_argument("--holdout", default=None,
                   help="CONDITION=VALUE: hold out one level, e.g. slip_angle=45 or group=smooth "
                        "(default: a random 30 %% of the conditions)")
    p.add_argument("--responses", nargs="+", default=None,
                   help="responses to fit: drawbar_pull lateral_force sinkage torque (default: those measured)")
    p.add_argument("--hidden", default=None, help="synthetic data only: mechanism to hide, or 'none' (default: random)")
    p.add_argument("--seed", type=int, default=0, help="random seed of the hold-out split and synthetic data")
    p.add_argument("--periodic", default=None, metavar="QUANTITY",
                   help="sweep folders: instead of the steady-state model, find the dominant oscillation of QUANTITY "
                        "(e.g. torque, drawbar_pull) in each run's series (tested against red noise) and the "
                        "frequency law that explains them (grouser passing, spoke stiffness, once per turn, "
                        "seed 002's slip-dependent wave); writes periodic.md and periodic.json to --report")
    p.add_argument("--group", default=None,
                   help="keep the rows whose group starts with this (e.g. ding2011: one rig and soil of the "
                        "digitised set; grouser or smooth in the CMU set)")
    p.add_argument("--test", default=None, metavar="TEST",
                   help="a second dataset (any supported format): fit on DATA, then predict TEST with the fitted "
                        "model and report its errors there (normalised by DATA's spread)")
    p.add_argument("--cv", default=None, metavar="CONDITION",
                   help="leave-one-condition-out cross-validation instead of one hold-out: each level of CONDITION "
                        "(slip_angle, load, gravity, slip, passes, grouser_height, group) held out in turn; writes "
                        "crossval.md and crossval.json to --report")
    p.add_argument("--shear-form", choices=("independent", "resultant"), default="independent",
                   help="the semi-empirical model's shear: 'independent' (classical: each direction saturates on its "
                        "own displacement) or 'resultant' (the CMU lab's model: one strength, shared along the slip "
                        "velocity)")
    p.add_argument("--domain", choices=("all", "driving"), default="all",
                   help="rows to use: 'all' (default: braking, dragged and 90 deg rows included; the report counts "
                        "each kind) or 'driving' (the classical subset: driving slip 0 <= i < 1 along the heading, "
                        "|slip angle| <= 80 deg)")
    p.add_argument("--resume", action="store_true",
                   help="with --cv: keep each finished fold in REPORT/folds and reuse those of the same data, "
                        "responses, seed and model on a later run")
    p.set_defaults(func=run_validate)

    p = sub.add_parser("predict", help="predict measured conditions with a model saved by 'wheelsoil validate'",
                       description="Rebuild the calibrated model from MODEL (the model.json that 'wheelsoil validate' "
                                   "writes beside its report) and predict every row of DATA: writes "
                                   "predictions.csv (measured, classical and final model per response) to --out and "
                                   "prints the errors.")
    p.add_argument("model", help="model.json written by 'wheelsoil validate'")
    p.add_argument("data", help="measured data (folder or CSV, any format 'wheelsoil validate' reads)")
    p.add_argument("--out", type=Path, default=Path("wheelsoil-output/predict"), help="output folder")
    p.add_argument("--group", default=None, help="keep the rows whose group starts with this")
    p.set_defaults(func=run_predict)


def run_predict(args) -> int:
    from wheelsoil.provenance import writable_folder
    from wheelsoil.validation.workflow import predict_command

    writable_folder(args.out, "--out")
    out = predict_command(args.model, args.data, out=args.out, group=args.group)
    console = Console()
    partial = [m for m in out["mechanisms"] if m not in out["named"]]
    console.print(f"model: classical + {' + '.join(out['mechanisms']) or 'nothing'}"
                  f"{' (partial, not named as causes: ' + ', '.join(partial) + ')' if partial else ''}; "
                  f"{out['rows']} rows")
    for q, e in out["errors"].items():
        console.print(f"  {q:14s} RMSE classical {e['baseline']['rmse']:.4g}, model {e['final']['rmse']:.4g} "
                      f"(normalised {e['baseline']['nrmse']:.3f} -> {e['final']['nrmse']:.3f}; {e['rows']} rows)")
    console.print(f"wrote {out['predictions']}")
    return 0


def run_validate(args) -> int:
    from wheelsoil.provenance import writable_folder

    if args.report is not None:
        writable_folder(args.report, "--report")  # before any fitting
    if args.data == "synthetic-periodic":
        from wheelsoil.validation.synthetic_periodic import synthetic_periodic_report

        command = "wheelsoil " + " ".join(args.argv)
        out = synthetic_periodic_report(args.hidden, seed=args.seed, report=args.report, command=command)
        console = Console()
        law = out["frequency_law"]
        console.print(f"frequency law: {law['found'] or 'none'} ({law['significant_runs']} significant runs)")
        if out["amplitude"]:
            for k, v in out["amplitude"]["models"].items():
                gain = f"  gain {v['gain']:+.3f} +- {v['gain_se']:.3f}" if "gain" in v else ""
                console.print(f"  {k:13s} {v['parameter']} = {v['value']:.4g}  BIC {v['bic']:7.1f}{gain}")
        console.print(f"found: {out['found'] or 'nothing'}; hidden: {out['hidden']['name'] or 'nothing'} "
                      f"{out['hidden']['parameters']}")
        console.print(f"wrote {out['report']}")
        return 0
    if args.periodic:
        from wheelsoil.validation.periodic import periodic_report

        from ..results import load_result

        command = "wheelsoil " + " ".join(args.argv)
        folder = Path(args.data)
        paths = sorted((folder / "cases").glob("*/result.h5"))
        if not paths:
            raise WheelsoilInputError(f"{folder} holds no finished runs (cases/*/result.h5); run 'wheelsoil batch' first")
        out = periodic_report([load_result(p) for p in paths], args.periodic, source=folder.name,
                              report=args.report, command=command)
        console = Console()
        for r in out["runs"]:
            console.print(f"  {r['case']}: f = {r['frequency_hz']:.2f} Hz, p = {r['p_value']:.1e}, "
                          f"{r['cycles']:.1f} cycles{'  significant' if r['significant'] else ''}")
        for config, found in out["configurations"].items():
            verdict = found["found"] or found.get("note") or "none within tolerance"
            if "unexplained" in found:
                verdict += f"; unexplained: {found['unexplained']}"
            console.print(f"{config}: frequency law: {verdict} ({found['significant_runs']} significant runs)")
        console.print(f"wrote {out['report']}")
        return 0
    from wheelsoil.validation.workflow import main_validate

    return main_validate(args)
