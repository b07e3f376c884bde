"""No module of the package imports itself through others (an import circle), counting the
imports inside functions: the layers contract (import-linter, make test) orders the stages,
this keeps the modules of one stage in order too."""
import grimp
import networkx as nx


def _circles(graph):
    """The groups of more than one module that import each other, round in a circle."""
    edges = nx.DiGraph((module, imported) for module in graph.modules
                       for imported in graph.find_modules_directly_imported_by(module))
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


def test_no_import_circles_in_the_package():
    assert _circles(grimp.build_graph("pipeline")) == []
