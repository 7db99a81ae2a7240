// One edited volume with bounded undo/redo: the document applies edit operations
// (edit_operation.h) through the tetops algorithms, reports what each changed so the live scene
// (live_scene.h) can update only what it must, and keeps the data to undo it.
//
// Undo data, per kind, the smallest that restores the mesh bit for bit (TetMesh::operator==):
//   paint, set_material   the changed tets and their old materials
//   move_piece            the piece's old transform
//   relax, deform         the moved vertices and their old positions
//   cut, fracture, weld,  a snapshot of the mesh before (every array changes: tets are removed or
//   refine                split, vertices renumbered or duplicated)
// Redo re-runs the operation: every operation is deterministic, so the result is identical, and the
// redo stack costs only the operations themselves.
//
// Memory: the undo entries' bytes are bounded by a budget (default 512 MiB); when a new entry would
// exceed it the oldest entries are dropped (counted in evicted_undo_count()). An entry larger than the
// whole budget is not kept at all (the edit then cannot be undone; the report says so).
//
// Not synchronised: one thread (or one lock) applies, undoes and redoes (see live_scene.h for the
// window's threading).
//
// The document always stores materials: a volume loaded without them gets the default material on
// every tet, so paint, undo and the solver all see one material per tet.
#pragma once

#include "scene/edit_operation.h"
#include "tetops/arap_deformation.h"
#include "tetops/connectivity.h"
#include "tetops/cut.h"
#include "tetops/exact_cut.h"
#include "tetops/fracture.h"
#include "tetops/fragments.h"
#include "tetops/paint.h"
#include "tetops/refine.h"
#include "tetops/relaxation.h"
#include "tetops/tet_mesh.h"

#include <array>
#include <cstddef>
#include <cstdint>
#include <deque>
#include <memory>
#include <iosfwd>
#include <optional>
#include <string>
#include <variant>
#include <vector>

namespace waxwork {

class Progress;

// A cut with relaxation: the tets it removed, then the relaxation of the cut vertices.
struct RelaxedCutResult {
    CutResult removal;
    RelaxationReport relaxation;
};

// What an operation's tetops algorithm reported, for callers that summarise it (the command line's
// JSON): RelaxedCutResult (plane and stroke cuts), ExactCutResult (exact cuts), RelaxationReport
// (relax), FractureResult, WeldResult, FragmentRemoval (remove_fragments), PaintResult, DragReport
// (deform), RefineResult; monostate for
// move_piece, set_material and undo. Only the counts: the per-vertex and per-tet arrays are left empty
// (the ones the scene needs are ChangeReport's own old_to_new_vertex, vertex_origins and
// changed_material_tets), so a report stays small.
using OperationResult = std::variant<std::monostate, RelaxedCutResult, ExactCutResult, RelaxationReport,
                                     FractureResult, WeldResult, FragmentRemoval, PaintResult, DragReport,
                                     RefineResult>;

// What an applied (or undone, or redone) operation changed. The live scene reacts to the flags.
struct ChangeReport {
    std::string name;           // operation name ("paint", ...), "undo paint", "redo paint"
    double milliseconds = 0;    // running the tetops algorithm(s) and recording undo data
    size_t tets_before = 0, tets_after = 0;
    size_t vertices_before = 0, vertices_after = 0;
    double min_dihedral_deg = 0;  // of the whole mesh afterwards (0 when empty)
    // Exact cut and exact fracture: tets left under min(0.5 degrees, their parent's angle) (split_quality.h).
    size_t tets_under_guard = 0;

    bool topology = false;         // tets/vertices added, removed or renumbered
    bool positions = false;        // rest positions moved (topology unchanged)
    std::vector<int32_t> moved_vertices;  // positions: exactly these vertices moved (ascending)
    bool piece_transforms = false; // one or more piece transforms changed
    bool all_materials = false;    // potentially every tet's material changed
    std::vector<int32_t> changed_material_tets;  // else: exactly these tets' materials changed (ascending)

    // Set by operations that build the new mesh's connectivity anyway (cut with relaxation): the
    // live scene reuses it instead of rebuilding. Null otherwise.
    std::shared_ptr<const TetConnectivity> connectivity;
    // Cut (exact or not), fracture, weld, refine, and undoing any of them: per vertex before, its index after
    // or -1 (lets the solver keep its warm start and rebuild its hierarchy around the change).
    std::vector<int32_t> old_to_new_vertex;
    // Exact cut, fracture and refine: per vertex after, where it comes from (vertex v, or the point of edge ab
    // it was made on). An index below vertices_before names a vertex before the change; a fracture's appended
    // vertices (crack copies, vertices on walls that cross earlier walls) may also name vertices after
    // with a lower index than their own (FractureResult::vertex_origins), so read in index order.
    std::vector<VertexOrigin> vertex_origins;

    bool undoable = true;       // false when the entry exceeded the whole undo budget
    size_t undo_entries_evicted = 0;  // oldest entries dropped to make room for this one
    std::string details;        // one line, operation specific (tets removed, vertices moved, ...)
    OperationResult result;     // the same counts, typed (applied and redone operations)

    bool anything_changed() const {
        return topology || positions || piece_transforms || all_materials || !changed_material_tets.empty();
    }
};

inline constexpr size_t kDefaultUndoBudgetBytes = size_t{512} << 20;

class Document {
public:
    // `default_material` is given to every tet when `mesh` stores no materials. Validates the mesh.
    explicit Document(TetMesh mesh, const TetMaterial& default_material,
                      size_t undo_budget_bytes = kDefaultUndoBudgetBytes);
    ~Document();
    Document(Document&&) noexcept;
    Document& operator=(Document&&) noexcept;

    const TetMesh& mesh() const { return mesh_; }
    double min_dihedral_deg() const { return min_dihedral_deg_; }

    // Runs the operation. On an exception (bad parameters, an algorithm failure, a cancel through
    // `progress`) the mesh is left as it was and nothing is recorded. Clears the redo stack. `progress`
    // (optional) follows the operations that can take seconds (deform).
    ChangeReport apply(const EditOperation& op, Progress* progress = nullptr);

    bool can_undo() const { return !undo_.empty(); }
    bool can_redo() const { return !redo_.empty(); }
    // nullopt when there is nothing to undo / redo.
    std::optional<ChangeReport> undo();
    std::optional<ChangeReport> redo();

    size_t undo_count() const { return undo_.size(); }
    size_t redo_count() const { return redo_.size(); }
    size_t undo_bytes() const { return undo_bytes_; }
    size_t undo_budget_bytes() const { return budget_; }
    size_t evicted_undo_count() const { return evicted_; }

    // The operations that made the current mesh from the loaded one, oldest first (applied and not
    // undone; evicted undo entries still count): the session record (session.h write_session).
    const std::vector<EditOperation>& history() const { return history_; }

    // --- Drag previews: the editor's Grab, Bend and Twist while the mouse moves. ---
    // A deform op's factorisation depends only on the grabbed body, its handle and pins and the rest
    // shape, so a drag factors once: the document keeps it while the positions stay those it was made
    // for (apply() of a deform reuses it too, with an identical result).
    //
    // preview_deform moves the vertices towards `op`'s full motion with `iterations` local/global
    // iterations warm-started from the previous preview of the same drag (guarded as apply() guards),
    // so a frame costs a few triangular solves. It makes no undo entry and no history; the first preview
    // remembers the positions before the drag, and its tets may not end under min(guard, their angle
    // then). Later previews must keep the op's grab, radius, pins and guard (the drag's handle):
    // InvalidArgumentError otherwise. The report is a positions change whose
    // moved_vertices are those that moved since the previous preview.
    ChangeReport preview_deform(const DeformOp& op, int iterations);
    bool previewing() const;
    // Ends the drag with `op` as the edit: the positions before the drag come back and `op` is applied
    // from them as apply() applies it (deterministic, so a session replays it bit for bit). The report's
    // moved_vertices are those whose position differs from the last preview's.
    ChangeReport commit_deform(const DeformOp& op);
    // Ends the drag without an edit: the positions before it come back (nullopt: no drag).
    std::optional<ChangeReport> cancel_deform();

private:
    // Exactly one kind of undo data is filled (see the top of this header).
    struct UndoEntry {
        EditOperation op;
        std::vector<int32_t> material_tets;           // paint, set_material
        std::vector<TetMaterial> old_materials;
        std::vector<int32_t> moved_vertices;          // relax
        std::vector<Eigen::Vector3d> old_positions;
        int piece = -1;                               // move_piece
        RigidTransform old_transform;
        std::shared_ptr<const TetMesh> snapshot;      // cut, fracture, weld
        // Cut, fracture and weld: per vertex after the edit, its vertex in the snapshot, or -1 (made
        // by the edit); undoing reports it as the change's vertex map, so the live scene keeps its warm start
        // and rebuilds its hierarchy around the change.
        std::vector<int32_t> snapshot_vertex;
        double old_min_dihedral_deg = 0;
        size_t bytes = 0;
    };
    ChangeReport run(const EditOperation& op, UndoEntry& entry, Progress* progress = nullptr);
    // The drag region and ARAP factorisation for `op` on the current positions (reused when they,
    // the body, the handle and the pins are those of the previous deform).
    struct DeformCache;
    DeformCache& deform_setup(const DeformOp& op);
    void require_no_preview(const char* what) const;
    // fracture, move_piece, weld (tetops/fracture.h).
    void run_piece_operation(const EditOperation& op, UndoEntry& entry, ChangeReport& report,
                             std::ostringstream& details);
    void push_undo(UndoEntry entry, ChangeReport& report);
    // Makes `after` the mesh, from an edit that kept every vertex at its index and appended the others
    // (fracture, refine): the vertex maps are identities, `origins` says where each vertex comes from,
    // and the mesh before becomes the undo snapshot.
    void adopt_appended(TetMesh after, std::vector<VertexOrigin> origins, double min_dihedral_deg, UndoEntry& entry,
                        ChangeReport& report);

    TetMesh mesh_;
    // Tet centroids for painting, built on the first stroke and kept until the geometry changes
    // (a kd-tree build costs more than a stroke at 500K tets). shared_ptr: PaintIndex stays opaque here.
    std::shared_ptr<PaintIndex> paint_index_;
    // The last deform's connectivity, region and factorisation (the mesh's connectivity is dropped
    // when the topology changes; the rest is checked against the positions on use).
    std::unique_ptr<DeformCache> deform_cache_;
    double min_dihedral_deg_ = 0;
    size_t budget_;
    size_t undo_bytes_ = 0;
    size_t evicted_ = 0;
    std::deque<UndoEntry> undo_;
    std::vector<EditOperation> redo_;  // most recently undone last
    std::vector<EditOperation> history_;
};

}  // namespace waxwork
