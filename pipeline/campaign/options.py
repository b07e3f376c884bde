"""A campaign's own options, declared as :func:`~pipeline.scenario.parameters.param`
fields of a frozen dataclass (the command line builds their flags:
:mod:`pipeline.cli._fields`).  ``__post_init__`` checks every value before any work;
:meth:`CampaignOptions.kwargs` gives the keyword options of the campaign's ``specs``."""
from dataclasses import dataclass, fields

from pipeline import paper
from pipeline.campaign.column_file import STIFFNESS_CHOICES, column_file_help, paper_rocking_hz
from pipeline.files import InputError
from pipeline.scenario.contact_file import refuse_set_twice
from pipeline.scenario.parameters import check_fields, param
from pipeline.scenario.contact_file import contact_values

CAMPAIGN_NOTE = ("the described column stands in the drums' place and a monolith of its "
                 "outline in the monolith's; a colonnade's description puts the colonnade "
                 "there instead (docs/colonnades.md)")
STIFFNESS_HELP = ("contact stiffness per point: matched raises the paper's kn for heavy "
                  "columns so that each rocks on its contact springs no slower than the "
                  f"paper's column ({paper_rocking_hz():.1f} Hz); paper: {paper.COLUMN_KN_N_M:g} N/m for all")


def column_file_param(note="", many=False, default=None, unset="the paper's column"):
    """The ``--column-file NAME_OR_FILE`` field; ``note``: what the campaign does with it,
    ``default`` its specimen when not given, else ``unset`` what it runs then."""
    return param(default, "", column_file_help(many) + (f"; {note}" if note else ""),
                 flag="--column-file", metavar="NAME_OR_FILE,..." if many else "NAME_OR_FILE",
                 optional=unset if default is None else None)


def stiffness_param(note="with --column-file"):
    """The ``--stiffness`` field: None when not given (matched, where a description is
    run), so that a combination that would ignore it is refused
    (:func:`refuse_ignored_stiffness`)."""
    return param(None, "", (f"{note}: " if note else "") + STIFFNESS_HELP,
                 flag="--stiffness", choices=STIFFNESS_CHOICES, optional="matched")


def contact_file_param(note=""):
    """The ``--contact-file JSON`` field (a file ``contact`` writes); ``note``: how the
    campaign uses it beside its own parameters."""
    return param(None, "", "contact parameters (kn, damping; mu_s, mu_k) from a file "
                 "`contact` writes, for every run" + (f"; {note}" if note else ""),
                 flag="--contact-file", metavar="JSON", optional=True)


def contact_of(options):
    """The contact values of an options object's ``contact_file`` (None without one),
    checked before any run."""
    if options.contact_file is None:
        return None
    return contact_values(options.contact_file)


def refuse_ignored_stiffness(options, contact, described=True):
    """InputError when ``--stiffness`` is given where nothing reads it: without a
    described column (``described`` False: the paper's column has the paper's kn) or
    beside a contact file that sets kn (the file's kn goes over it)."""
    if options.stiffness is None:
        return
    if not described:
        raise InputError("--stiffness sets a described column's kn: add --column-file (the "
                         "paper's column has the paper's kn)")
    refuse_set_twice(contact, ["kn"], "--stiffness")


@dataclass(frozen=True)
class CampaignOptions:
    """No options of its own.  Subclasses declare fields and may add :meth:`check`."""
    TAKES_JOBS = False          # the specs want the command's --jobs (keyword ``jobs``)
    DRIVER_ONLY = ()            # options only the campaign's driver reads, not its specs

    def __post_init__(self):
        check_fields(self)
        self.check()

    def check(self):
        """Checks across fields (InputError)."""

    def kwargs(self):
        """Keyword options of the campaign (its driver's; its ``specs`` take them less
        :attr:`DRIVER_ONLY`, every other one by name)."""
        return {f.name: getattr(self, f.name) for f in fields(self)}


@dataclass(frozen=True)
class ColumnFileOptions(CampaignOptions):
    """A campaign of the twin model that can shake a described column instead."""
    column_file: str = column_file_param(CAMPAIGN_NOTE)
    stiffness: str = stiffness_param()
    contact_file: str = contact_file_param(
        "with --column-file its kn replaces --stiffness's")

    def check(self):
        refuse_ignored_stiffness(self, contact_of(self), self.column_file is not None)
