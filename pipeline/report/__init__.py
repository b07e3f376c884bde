"""Report stage: results/REPORT.md from the campaigns' tables and figures.

    python -m pipeline report

Sections for campaigns that have not run say so instead of inventing numbers.  One module
per kind of section: ``records`` (records, processing, synthetics), ``campaigns``
(verification, sweeps, real columns, shake table, speed, run-all's cost), ``colonnades``
(a colonnade under records), ``ensembles``
(ensembles, the paper's question, convergence), ``contact_stiffness``, ``fragility``,
``inversion``; shared helpers in ``common``."""
import datetime
import json
from pathlib import Path

from pipeline import RESULTS_DIR, __version__
from pipeline.files import write_text
from pipeline.report.campaigns import (columns_section, run_all_section, shake_table_section,
                                       speed_section, sweep_section, verification_section)
from pipeline.report.colonnades import colonnade_section, directions_section
from pipeline.report.contact_stiffness import contact_stiffness_section
from pipeline.report.ensembles import (convergence_section, ensemble_section,
                                       paper_question_section)
from pipeline.report.fragility import fragility_section, rock_fragility_section
from pipeline.report.field_rock import FIELD_ROCK_QUICK, field_rock_section
from pipeline.report.hazard import survival_section
from pipeline.report.hazard_routes import hazard_routes_section
from pipeline.report.inversion import inversion_section
from pipeline.report.member_study import member_study_section
from pipeline.report.shake_table_scores import QUICK as SCORES_QUICK
from pipeline.report.shake_table_scores import shake_table_scores_section
from pipeline.report.records import (back_azimuth_table, correlation_table, per_record_table,
                                     processing_section, record_orientation, records_section,
                                     records_statements, synthetic_section, toppled_fractions,
                                     with_back_azimuth)
from pipeline.stats.ensemble import wilson_interval

__all__ = ["build_report", "back_azimuth_table", "colonnade_section", "columns_section",
           "contact_stiffness_section", "convergence_section", "field_rock_section",
           "correlation_table", "hazard_routes_section", "paper_question_section",
           "ensemble_section", "fragility_section", "inversion_section",
           "member_study_section", "per_record_table",
           "processing_section", "record_orientation", "records_section", "records_statements",
           "rock_fragility_section", "run_all_section",
           "shake_table_scores_section", "shake_table_section", "speed_section", "survival_section", "sweep_section",
           "synthetic_section",
           "toppled_fractions", "verification_section", "wilson_interval", "with_back_azimuth"]


def build_report(results=RESULTS_DIR):
    results = Path(results)
    campaigns = {}
    for name in ("verification", "slenderness", "friction", "records", "synthetic", "ensemble",
                 "paper-question", "convergence", "fragility", "columns"):
        meta = results / name / "campaign.json"
        if meta.exists():
            campaigns[name] = json.loads(meta.read_text())
    head = ["# Toppling columns: results report\n",
            f"Generated {datetime.datetime.now(datetime.timezone.utc):%Y-%m-%d %H:%M} UTC by "
            f"toppling-columns {__version__}, after Hinzen (2009), BSSA 99(5).\n",
            "Campaigns: " + (", ".join(f"{n} ({c.get('runs', '?')} runs)"
                                       for n, c in campaigns.items()) or "none") + "\n"]
    body = [
        verification_section(results),
        sweep_section(results, "slenderness", "hd",
                      "GM20 toppled the drum column for h/d >= 3.5 and the monolith for "
                      "h/d >= 4.0; the drum column's downfall directions varied strongly with "
                      "h/d, the monolith's grouped NNE and SSE within 30 deg. The pulse record "
                      "(paper GM23) toppled both columns toward one direction (42 deg cone), "
                      "transverse to the back azimuth."),
        sweep_section(results, "friction", "mu_s",
                      "friction had a minor influence on downfall directions; with mu_s = 0.1 "
                      "neither column toppled (they slid instead)."),
        shake_table_section(results), shake_table_scores_section(results),
        shake_table_scores_section(results, SCORES_QUICK), contact_stiffness_section(results),
        rock_fragility_section(results),
        rock_fragility_section(results, "rock-fragility-table"), survival_section(results),
        field_rock_section(results), field_rock_section(results, FIELD_ROCK_QUICK),
        hazard_routes_section(results),
        paper_question_section(results), ensemble_section(results),
        convergence_section(results), fragility_section(results), columns_section(results),
        colonnade_section(results), directions_section(results),
        inversion_section(results), member_study_section(results),
        records_section(results), processing_section(results), synthetic_section(results),
        speed_section(results), run_all_section(results)]
    text = "\n".join(head + body)
    write_text(results / "REPORT.md", text)
    return results / "REPORT.md"


# ---------------------------------------------------------------- source inversion
