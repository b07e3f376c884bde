"""No module of the package imports itself through others (an import circle), counting the
imports inside functions: the layers contract (import-linter, make test) orders the stages,
this keeps the modules of one stage in order too.  Importing ``a.b.c`` runs the packages
``a.b`` and ``a`` first: from outside a package, an import of one of its modules counts as
an import of the package too (its ``__init__`` may import the importer back)."""
import grimp
import networkx as nx


def _packages_run(importer, imported):
    """The packages that importing ``imported`` runs first, less those ``importer`` is in."""
    parts = imported.split(".")
    for i in range(2, len(parts)):
        package = ".".join(parts[:i])
        if importer != package and not importer.startswith(package + "."):
            yield package


def _circles(graph):
    """The groups of more than one module that import each other, round in a circle."""
    edges = nx.DiGraph()
    for module in graph.modules:
        for imported in graph.find_modules_directly_imported_by(module):
            edges.add_edge(module, imported)
            edges.add_edges_from((module, package) for package in
                                 _packages_run(module, imported) if package in graph.modules)
    return sorted(sorted(group) for group in nx.strongly_connected_components(edges)
                  if len(group) > 1)


def test_the_circle_finder_finds_a_circle():
    graph = grimp.ImportGraph()
    for name in ("p", "p.a", "p.b", "p.c"):
        graph.add_module(name)
    graph.add_import(importer="p.a", imported="p.b")
    graph.add_import(importer="p.b", imported="p.a")
    graph.add_import(importer="p.c", imported="p.a")
    assert _circles(graph) == [["p.a", "p.b"]]


def test_a_circle_through_a_package_init_is_found():
    """p.x imports p.pkg.kinds, which runs p.pkg's __init__, which imports p.pkg.load, which
    imports p.x: ``python -c "import p.x"`` fails, though no two modules name each other."""
    graph = grimp.ImportGraph()
    for name in ("p", "p.x", "p.pkg", "p.pkg.kinds", "p.pkg.load"):
        graph.add_module(name)
    graph.add_import(importer="p.x", imported="p.pkg.kinds")
    graph.add_import(importer="p.pkg", imported="p.pkg.load")
    graph.add_import(importer="p.pkg", imported="p.pkg.kinds")
    graph.add_import(importer="p.pkg.load", imported="p.x")
    assert _circles(graph) == [["p.pkg", "p.pkg.load", "p.x"]]


def test_no_import_circles_in_the_package():
    assert _circles(grimp.build_graph("pipeline")) == []
