"""The contact file (JSON) that ``contact`` writes and ``run --contact-file`` reads: the
contact parameters a free-rocking test gave (``kn`` N/m per point, ``damping``; also
``mu_s``, ``mu_k`` when stated) beside what they came from (``restitution`` and its
uncertainty, the block, the source: informational keys, not read)."""
import re
from pathlib import Path

from pipeline.files import InputError
from pipeline.scenario.parameters import Contact
from pipeline.userfiles import keys_text, number, read_json, read_user_bytes
import hashlib

CONTACT_KEYS = ("kn", "damping", "mu_s", "mu_k")
INFORMATION_KEYS = ("restitution", "restitution_sd", "restitution_se", "impacts",
                    "restitution_per_impact", "housner_restitution", "block", "source",
                    "damping_map", "damping_interval", "specimen")


def load_contact_file(path):
    """{Contact field: value} of a contact file (values range-checked by
    :class:`~pipeline.scenario.parameters.Contact` where used); one-line InputError for a
    missing or unreadable file, an unknown key, or a file without kn and damping."""
    path = Path(path)
    data = read_json(path, "--contact-file")
    if not isinstance(data, dict):
        raise InputError(f"--contact-file {path.name}: a JSON object needed")
    unknown = set(data) - set(CONTACT_KEYS) - set(INFORMATION_KEYS)
    if unknown:
        raise InputError(f"--contact-file {path.name}: unknown key(s) {keys_text(unknown)} "
                         f"(known: {', '.join(CONTACT_KEYS + INFORMATION_KEYS)})")
    values = {k: number(data[k], f"--contact-file {path.name}: '{k}'")
              for k in CONTACT_KEYS if data.get(k) is not None}
    if "damping" not in values or "kn" not in values:
        raise InputError(f"--contact-file {path.name}: no kn and damping (a restitution "
                         "alone: give `contact` --damping-map to map it onto the contact law)")
    return values


def contact_values(path):
    """The contact fields a contact file sets, range-checked by
    :class:`~pipeline.scenario.parameters.Contact` (one-line InputError); a file that sets
    mu_s without mu_k gets the kinetic friction a run gives that mu_s."""
    values = load_contact_file(path)
    contact = checked_contact(values, path)
    if "mu_s" in values and "mu_k" not in values:
        values["mu_k"] = contact.mu_k
    return values


def checked_contact(values: dict[str, float], path: Path, **flags: float) -> Contact:
    """The :class:`~pipeline.scenario.parameters.Contact` of a contact file's ``values``
    and the command line's ``flags`` (the other contact fields); a value out of range is
    one InputError naming the file and its key when the file gave it, the flag when the
    command line did."""
    try:
        return Contact(**flags, **values)
    except InputError as exc:        # the range check names the option: name the file's key
        flag = re.match(r"^--([a-z][a-z0-9-]*)", str(exc))
        if flag is None or (flags and flag[1].replace("-", "_") not in values):
            raise
        message = re.sub(r"^--([a-z][a-z0-9-]*)",
                         lambda m: repr(m[1].replace("-", "_")), str(exc))
        raise InputError(f"--contact-file {Path(path).name}: {message}") from None


def contact_provenance(path):
    """What a campaign records of the contact file it ran with: the file, its SHA-256
    and the contact values taken from it."""
    path = Path(path)
    return {"file": str(path), "sha256": hashlib.sha256(read_user_bytes(path, "--contact-file")).hexdigest(),
            "values": contact_values(path)}


def with_contact(runs, values):
    """(record, parameters) pairs with a contact file's ``values`` over each run's
    contact fields (unchanged for None)."""
    if not values:
        return list(runs)
    return [(record, {**params, **values}) for record, params in runs]


def refuse_set_twice(values, fields, what):
    """One-line InputError when the contact file sets a field that ``what`` (a flag or
    the campaign's own sweep) sets too."""
    both = [k for k in fields if k in (values or {})]
    if both:
        raise InputError(f"--contact-file sets {', '.join(both)}, which {what} sets too: "
                         "give it in one place, not both")


def file_fields(name):
    """The contact file's fields a sampled range ``name`` stands for: ``mu_s`` the friction
    pair (mu_s, mu_k), any other name its own field."""
    return ("mu_s", "mu_k") if name == "mu_s" else (name,)


def ranges_left(ranges, contact, given, what):
    """``ranges`` (name -> range) without those a contact file fixes (``contact``: its
    values, or None: all kept): a range is not drawn when the file sets one of its
    :func:`file_fields`.  A range named in ``given`` (the names the flag ``what`` gives)
    whose field the file sets is refused (one line, :func:`refuse_set_twice`)."""
    if not contact:
        return dict(ranges)
    refuse_set_twice(contact, [f for name in given for f in file_fields(name)], what)
    return {k: v for k, v in ranges.items() if not any(f in contact for f in file_fields(k))}
