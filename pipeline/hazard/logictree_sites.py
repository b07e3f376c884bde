"""A plain logic-tree table with a ``site`` column (its last): the rows of one site, the
column taken off, for :func:`pipeline.hazard.logictree.load_logic_tree` (specimens at
several sites of one table: ``constrain --specimen-site``)."""
from pipeline.files import InputError
from pipeline.userfiles import show

SITE_COLUMN = "site"


def plain_site_rows(path, lines, site):
    """``lines`` of a plain table as they would be without its site column, the rows of
    other sites than ``site`` (a 0-based integer; None: the table's only site) blanked as
    comments (the lines keep their numbers); ``lines`` unchanged when the table has no
    site column (then ``site`` must be None)."""
    return plain_site_tables(path, lines, [site])[0]


def plain_site_tables(path, lines, sites):
    """:func:`plain_site_rows` of each of ``sites``, the table split by site once."""
    body = [k for k, line in enumerate(lines) if line and not line.startswith("#")]
    names = [n.strip().lower() for n in lines[body[0]].split(",")]
    if names[-1] != SITE_COLUMN:
        if any(site is not None for site in sites):
            raise InputError(f"--site applies to OpenQuake curves with several sites or a "
                             f"plain table with a site column; {path} has none")
        return [lines for _ in sites]
    rows = {}
    for k in body[1:]:
        cells = [c.strip() for c in lines[k].split(",")]
        try:
            index = int(cells[-1])
        except ValueError:
            raise InputError(f"{path}, line {k + 1}: site {show(cells[-1])} is not a site "
                             "index (an integer from 0)") from None
        if index < 0:
            raise InputError(f"{path}, line {k + 1}: site {index} (from 0)")
        rows.setdefault(index, []).append(k)
    return [_one_site(path, lines, body[0], rows, site) for site in sites]


def _one_site(path, lines, header, rows, site):
    """The lines of ``site`` (None: the only one) with the other sites' rows as comments
    (the lines keep their numbers) and the site column taken off."""
    if site is None:
        if len(rows) != 1:
            raise InputError(f"{path}: {len(rows)} sites in the table: name one (--site, "
                             "--specimen-site)")
        site = next(iter(rows))
    if site not in rows:
        raise InputError(f"{path}: site {site} beyond the table's sites "
                         f"({', '.join(map(str, sorted(rows)))})")
    keep = {header, *rows[site]}
    return [line.rsplit(",", 1)[0] if k in keep else "#" for k, line in enumerate(lines)]
