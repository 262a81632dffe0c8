// The builder: runs its phases in order over one BuildContext. See builder.h.
#include "builder.h"

#include "build_checks.h"
#include "build_csg.h"
#include "build_exprs.h"
#include "build_names.h"
#include "build_scene.h"
#include "build_state.h"

namespace pcsg {

namespace {

// Upper bounds from the AST, so that no array of the graph is copied while it grows.
void reserve(Graph& g, const Ast& ast) {
    const size_t csg = ast.csg.size(), exprs = ast.exprs.size(), lists = ast.lists.size();
    g.nodes.reserve(csg + ast.stmts.size() + 16);
    g.edges.reserve(lists + csg + ast.stmts.size() + 16);
    g.exprs.reserve(exprs + 16);
    g.code.reserve(2 * exprs + 3 * ast.chainItems.size() + 16);
    g.args.reserve(lists + 16);
    g.assignments.reserve(ast.assigns.size() + lists + 16);
    g.calcs.reserve(csg + 16);
    g.transforms.reserve(csg + 16);
    g.primitives.reserve(csg + 16);
}

}  // namespace

std::optional<Graph> build(const Source& src, const TokenStream& tokens, const Ast& ast,
                           Diagnostics& diags) {
    const size_t errorsBefore = diags.count();
    BuildContext ctx{src, tokens.tokens, ast, diags, Graph{}};
    ctx.g.files = diags.fileNames();
    reserve(ctx.g, ast);
    Names names;
    for (uint32_t tok : ast.droppedNames) names.droppedNames.insert(ctx.text(tok));
    ExprCompiler exprs(ctx, names);

    // The order matters beyond the data each phase needs: it is the order of the
    // diagnostics, and of the parameter slots and rand() call sites in the graph.
    ctx.g.materials.push_back(Material{.name = "default"});
    readSettings(ctx, exprs);
    declareMaterials(ctx, names);
    readDirectives(ctx, names, exprs);
    resolveNames(ctx, names);
    lowerCsg(ctx, names, exprs);
    checkTriangles(ctx);
    addDefaultLight(ctx);
    if (diags.count() != errorsBefore) return std::nullopt;
    return std::move(ctx.g);
}

}  // namespace pcsg
