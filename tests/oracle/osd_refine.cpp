// OpenSubdiv oracle for affinity.subdivision's tests: uniform refinement of an OBJ mesh with Far
// (level points, not projected to the limit: what Blender's Subdivision Surface gives with
// use_limit_surface=False), its texture coordinates as a face-varying channel, and the limit surface's
// uv evaluated with Bfr. Build with `make` in this folder (Debian: libosd-dev).
//
// Usage: osd_refine MESH.obj [--scheme catmark|bilinear] [--level L] [--boundary none|edgeOnly|edgeAndCorner]
//        [--fvar none|cornersOnly|cornersPlus1|cornersPlus2|boundaries|all]
//        [--crease A B SHARPNESS]... [--corner V SHARPNESS]... [--hole F]... [--limit-samples N]
// Vertex and face indices on the command line are 0-based.
//
// Output (text, one record per line, every number with 17 significant digits):
//   counts V FV F                      refined vertices, uv values and faces at level L
//   v x y z                            V lines: refined positions
//   t u v                              FV lines: refined uv values
//   f BASE HOLE n i0 .. in-1 j0 .. jn-1  F lines: base face, hole flag, vertex indices, uv indices
//   d BASE SAMPLE u v lu lv cu cv      with --limit-samples N > 0: per base face, per sample (u, v) of Bfr's
//                                      parameterization, the limit uv (lu, lv) under --fvar and the cage's
//                                      bilinear uv (cu, cv) (the same face's uv under the linear rule `all`)
#include <opensubdiv/far/primvarRefiner.h>
#include <opensubdiv/far/topologyDescriptor.h>
#include <opensubdiv/bfr/refinerSurfaceFactory.h>
#include <opensubdiv/bfr/surface.h>

#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

using namespace OpenSubdiv;
typedef Far::TopologyDescriptor Descriptor;

struct Point3 {
    double p[3];
    void Clear() { p[0] = p[1] = p[2] = 0; }
    void AddWithWeight(Point3 const &s, double w) { for (int k = 0; k < 3; ++k) p[k] += w * s.p[k]; }
};
struct Point2 {
    double p[2];
    void Clear() { p[0] = p[1] = 0; }
    void AddWithWeight(Point2 const &s, double w) { for (int k = 0; k < 2; ++k) p[k] += w * s.p[k]; }
};

static void fail(const char *what) { std::fprintf(stderr, "osd_refine: %s\n", what); std::exit(2); }

static int parse_index(const std::string &token, int count) {
    int i = std::atoi(token.c_str());
    return i < 0 ? count + i : i - 1;
}

struct Obj {
    std::vector<Point3> positions;
    std::vector<Point2> uvs;
    std::vector<int> sizes, verts, uvIndices;
};

static Obj read_obj(const char *path) {
    std::ifstream in(path);
    if (!in) fail("cannot read the mesh");
    Obj obj;
    std::string line;
    while (std::getline(in, line)) {
        std::istringstream s(line);
        std::string tag;
        s >> tag;
        if (tag == "v") {
            Point3 p; s >> p.p[0] >> p.p[1] >> p.p[2]; obj.positions.push_back(p);
        } else if (tag == "vt") {
            Point2 t; s >> t.p[0] >> t.p[1]; obj.uvs.push_back(t);
        } else if (tag == "f") {
            std::string corner;
            int n = 0;
            while (s >> corner) {
                std::string v = corner.substr(0, corner.find('/'));
                obj.verts.push_back(parse_index(v, (int)obj.positions.size()));
                size_t slash = corner.find('/');
                if (slash == std::string::npos || corner[slash + 1] == '/') fail("every corner needs a uv (v/vt)");
                std::string t = corner.substr(slash + 1, corner.find('/', slash + 1) - slash - 1);
                obj.uvIndices.push_back(parse_index(t, (int)obj.uvs.size()));
                ++n;
            }
            obj.sizes.push_back(n);
        }
    }
    return obj;
}

static Sdc::Options::VtxBoundaryInterpolation boundary_rule(const std::string &name) {
    if (name == "none") return Sdc::Options::VTX_BOUNDARY_NONE;
    if (name == "edgeOnly") return Sdc::Options::VTX_BOUNDARY_EDGE_ONLY;
    if (name == "edgeAndCorner") return Sdc::Options::VTX_BOUNDARY_EDGE_AND_CORNER;
    fail("unknown boundary rule");
    return Sdc::Options::VTX_BOUNDARY_NONE;
}

static Sdc::Options::FVarLinearInterpolation fvar_rule(const std::string &name) {
    if (name == "none") return Sdc::Options::FVAR_LINEAR_NONE;
    if (name == "cornersOnly") return Sdc::Options::FVAR_LINEAR_CORNERS_ONLY;
    if (name == "cornersPlus1") return Sdc::Options::FVAR_LINEAR_CORNERS_PLUS1;
    if (name == "cornersPlus2") return Sdc::Options::FVAR_LINEAR_CORNERS_PLUS2;
    if (name == "boundaries") return Sdc::Options::FVAR_LINEAR_BOUNDARIES;
    if (name == "all") return Sdc::Options::FVAR_LINEAR_ALL;
    fail("unknown face-varying rule");
    return Sdc::Options::FVAR_LINEAR_ALL;
}

static Far::TopologyRefiner *make_refiner(const Obj &obj, Sdc::SchemeType scheme, Sdc::Options options,
                                          const std::vector<int> &creasePairs, const std::vector<float> &creaseWeights,
                                          const std::vector<int> &corners, const std::vector<float> &cornerWeights,
                                          const std::vector<int> &holes) {
    Descriptor desc;
    desc.numVertices = (int)obj.positions.size();
    desc.numFaces = (int)obj.sizes.size();
    desc.numVertsPerFace = obj.sizes.data();
    desc.vertIndicesPerFace = obj.verts.data();
    desc.numCreases = (int)creaseWeights.size();
    desc.creaseVertexIndexPairs = creasePairs.data();
    desc.creaseWeights = creaseWeights.data();
    desc.numCorners = (int)cornerWeights.size();
    desc.cornerVertexIndices = corners.data();
    desc.cornerWeights = cornerWeights.data();
    desc.numHoles = (int)holes.size();
    desc.holeIndices = holes.data();
    Descriptor::FVarChannel channel;
    channel.numValues = (int)obj.uvs.size();
    channel.valueIndices = obj.uvIndices.data();
    desc.numFVarChannels = 1;
    desc.fvarChannels = &channel;
    Far::TopologyRefiner *refiner = Far::TopologyRefinerFactory<Descriptor>::Create(
        desc, Far::TopologyRefinerFactory<Descriptor>::Options(scheme, options));
    if (!refiner) fail("OpenSubdiv could not build the topology");
    return refiner;
}

// Per base face, N x N samples of Bfr's parameterization (each quad sub-face's N x N grid, corner to centre,
// for n-gons; (N + 1)(N + 2) / 2 points of the triangle for triangles): the limit uv under `refiner`'s face-varying rule and under `linear`'s (the rule `all`).
static void write_limit_samples(Far::TopologyRefiner &refiner, Far::TopologyRefiner &linear, const Obj &obj, int N) {
    typedef Bfr::RefinerSurfaceFactory<> Factory;
    Factory smooth(refiner), flat(linear);
    Bfr::Surface<double> surface, cage;
    const double *uvData = &obj.uvs[0].p[0];
    std::vector<double> patch, cagePatch;
    for (int face = 0; face < refiner.GetLevel(0).GetNumFaces(); ++face) {
        if (!smooth.InitFaceVaryingSurface(face, &surface, 0) || !flat.InitFaceVaryingSurface(face, &cage, 0)) {
            fail("Bfr could not build a face-varying surface");
        }
        patch.resize(surface.GetNumPatchPoints() * 2);
        cagePatch.resize(cage.GetNumPatchPoints() * 2);
        surface.PreparePatchPoints(uvData, 2, patch.data(), 2);
        cage.PreparePatchPoints(uvData, 2, cagePatch.data(), 2);
        Bfr::Parameterization param = surface.GetParameterization();
        int size = param.GetFaceSize();
        int subfaces = param.GetType() == Bfr::Parameterization::QUAD_SUBFACES ? size : 1;
        int sample = 0;
        for (int sub = 0; sub < subfaces; ++sub) {
            for (int j = 0; j <= N; ++j) {
                for (int i = 0; i <= N; ++i) {
                    double st[2] = {i / (double)N, j / (double)N}, uv[2];
                    if (param.GetType() == Bfr::Parameterization::TRI && i + j > N) continue;
                    if (subfaces > 1) {
                        param.ConvertNormalizedSubFaceToCoord(sub, st, uv);
                    } else {
                        uv[0] = st[0]; uv[1] = st[1];
                    }
                    double limit[2], bilinear[2];
                    surface.Evaluate(uv, patch.data(), 2, limit);
                    cage.Evaluate(uv, cagePatch.data(), 2, bilinear);
                    std::printf("d %d %d %.17g %.17g %.17g %.17g %.17g %.17g\n", face, sample++, uv[0], uv[1],
                                limit[0], limit[1], bilinear[0], bilinear[1]);
                }
            }
        }
    }
}

int main(int argc, char **argv) {
    if (argc < 2) fail("usage: osd_refine MESH.obj [options]");
    Sdc::SchemeType scheme = Sdc::SCHEME_CATMARK;
    Sdc::Options options;
    options.SetVtxBoundaryInterpolation(Sdc::Options::VTX_BOUNDARY_EDGE_AND_CORNER);
    options.SetFVarLinearInterpolation(Sdc::Options::FVAR_LINEAR_CORNERS_PLUS1);
    int level = 1, samples = 0;
    std::vector<int> creasePairs, corners, holes;
    std::vector<float> creaseWeights, cornerWeights;
    for (int a = 2; a < argc; ++a) {
        std::string arg = argv[a];
        bool more = a + 1 < argc;
        if (arg == "--scheme" && more) {
            std::string name = argv[++a];
            scheme = name == "bilinear" ? Sdc::SCHEME_BILINEAR : Sdc::SCHEME_CATMARK;
        } else if (arg == "--level" && more) {
            level = std::atoi(argv[++a]);
        } else if (arg == "--boundary" && more) {
            options.SetVtxBoundaryInterpolation(boundary_rule(argv[++a]));
        } else if (arg == "--fvar" && more) {
            options.SetFVarLinearInterpolation(fvar_rule(argv[++a]));
        } else if (arg == "--crease" && a + 3 < argc) {
            creasePairs.push_back(std::atoi(argv[++a]));
            creasePairs.push_back(std::atoi(argv[++a]));
            creaseWeights.push_back((float)std::atof(argv[++a]));
        } else if (arg == "--corner" && a + 2 < argc) {
            corners.push_back(std::atoi(argv[++a]));
            cornerWeights.push_back((float)std::atof(argv[++a]));
        } else if (arg == "--hole" && more) {
            holes.push_back(std::atoi(argv[++a]));
        } else if (arg == "--limit-samples" && more) {
            samples = std::atoi(argv[++a]);
        } else {
            fail(("unknown or incomplete option " + arg).c_str());
        }
    }
    Obj obj = read_obj(argv[1]);
    Far::TopologyRefiner *refiner =
        make_refiner(obj, scheme, options, creasePairs, creaseWeights, corners, cornerWeights, holes);
    refiner->RefineUniform(Far::TopologyRefiner::UniformOptions(level));

    std::vector<Point3> positions(refiner->GetNumVerticesTotal());
    std::vector<Point2> uvs(refiner->GetNumFVarValuesTotal(0));
    std::copy(obj.positions.begin(), obj.positions.end(), positions.begin());
    std::copy(obj.uvs.begin(), obj.uvs.end(), uvs.begin());
    Far::PrimvarRefinerReal<double> primvar(*refiner);
    Point3 *src = positions.data();
    Point2 *srcUv = uvs.data();
    for (int l = 1; l <= level; ++l) {
        Point3 *dst = src + refiner->GetLevel(l - 1).GetNumVertices();
        Point2 *dstUv = srcUv + refiner->GetLevel(l - 1).GetNumFVarValues(0);
        primvar.Interpolate(l, src, dst);
        primvar.InterpolateFaceVarying(l, srcUv, dstUv, 0);
        src = dst;
        srcUv = dstUv;
    }
    Far::TopologyLevel const &last = refiner->GetLevel(level);
    std::printf("counts %d %d %d\n", last.GetNumVertices(), last.GetNumFVarValues(0), last.GetNumFaces());
    for (int v = 0; v < last.GetNumVertices(); ++v)
        std::printf("v %.17g %.17g %.17g\n", src[v].p[0], src[v].p[1], src[v].p[2]);
    for (int t = 0; t < last.GetNumFVarValues(0); ++t)
        std::printf("t %.17g %.17g\n", srcUv[t].p[0], srcUv[t].p[1]);
    for (int f = 0; f < last.GetNumFaces(); ++f) {
        int base = f;
        for (int l = level; l > 0; --l) base = refiner->GetLevel(l).GetFaceParentFace(base);
        Far::ConstIndexArray verts = last.GetFaceVertices(f), values = last.GetFaceFVarValues(f, 0);
        std::printf("f %d %d %d", base, last.IsFaceHole(f) ? 1 : 0, verts.size());
        for (int k = 0; k < verts.size(); ++k) std::printf(" %d", verts[k]);
        for (int k = 0; k < values.size(); ++k) std::printf(" %d", values[k]);
        std::printf("\n");
    }
    if (samples > 0) {
        Sdc::Options flat = options;
        flat.SetFVarLinearInterpolation(Sdc::Options::FVAR_LINEAR_ALL);
        Far::TopologyRefiner *linear =
            make_refiner(obj, scheme, flat, creasePairs, creaseWeights, corners, cornerWeights, holes);
        Far::TopologyRefiner *base =
            make_refiner(obj, scheme, options, creasePairs, creaseWeights, corners, cornerWeights, holes);
        write_limit_samples(*base, *linear, obj, samples);
        delete linear;
        delete base;
    }
    delete refiner;
    return 0;
}
