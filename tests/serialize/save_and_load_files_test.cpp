// save() and the file loaders at the edges of the file system: a save that cannot be written is an
// Error naming the file and leaves the old file whole and nothing beside it; special files are
// written in place (and stay special files); a link is followed, not replaced. Loading refuses
// files that never end or never deliver, and reports a missing file as FileNotFoundError.
#include <gtest/gtest.h>
#include <sys/resource.h>

#include <csignal>
#include <fstream>
#include <iterator>
#include <string>

#include "bvhkit/io/closest_point_mesh_file.hpp"
#include "bvhkit/io/collision_model_file.hpp"
#include "bvhkit/io/signed_distance_mesh_file.hpp"
#include "bvhkit/io/triangle_bvh_file.hpp"
#include "bvhkit/io/winding_number_mesh_file.hpp"
#include "bvhkit/mesh/procedural.hpp"
#include "special_files.hpp"

using namespace bvhkit;

namespace {

std::string save_error_of(const std::function<void()>& body) {
    try {
        body();
    } catch (const Error& e) {
        return e.what();
    }
    return "(no error)";
}

std::string file_text(const std::filesystem::path& p) {
    std::ifstream in(p, std::ios::binary);
    return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

// Every structure's save, on one small sphere.
std::vector<std::pair<std::string, std::function<void(const std::filesystem::path&)>>> savers() {
    const TriangleMesh mesh = make_procedural("sphere:subdiv=3");
    return {
        {"TriangleBvh", [mesh](const auto& p) { save(TriangleBvh<float>(mesh), p); }},
        {"ClosestPointMesh", [mesh](const auto& p) { save(ClosestPointMesh<float>(mesh), p); }},
        {"SignedDistanceMesh",
         [mesh](const auto& p) { save(SignedDistanceMesh<double>(mesh), p); }},
        {"WindingNumberMesh", [mesh](const auto& p) { save(WindingNumberMesh<float>(mesh), p); }},
        {"CollisionModel", [mesh](const auto& p) { save(CollisionModel<Obb<float>>(mesh), p); }},
    };
}

// While alive, files of this process may grow to `bytes` only, and going past fails the write
// with EFBIG instead of ending the process: the nearest thing to a full disk a test can make.
class FileSizeLimit {
  public:
    explicit FileSizeLimit(rlim_t bytes) {
        ::getrlimit(RLIMIT_FSIZE, &old_);
        old_handler_ = std::signal(SIGXFSZ, SIG_IGN);
        rlimit limit = old_;
        limit.rlim_cur = bytes;
        ok_ = ::setrlimit(RLIMIT_FSIZE, &limit) == 0;
    }
    FileSizeLimit(const FileSizeLimit&) = delete;
    FileSizeLimit& operator=(const FileSizeLimit&) = delete;
    ~FileSizeLimit() {
        ::setrlimit(RLIMIT_FSIZE, &old_);
        std::signal(SIGXFSZ, old_handler_);
    }
    bool ok() const { return ok_; }

  private:
    rlimit old_{};
    void (*old_handler_)(int) = nullptr;
    bool ok_ = false;
};

}  // namespace

TEST(SaveFiles, FullDeviceIsAnErrorNamingIt) {
    for (const auto& [name, save_to] : savers()) {
        const std::string message = save_error_of([&] { save_to("/dev/full"); });
        EXPECT_NE(message.find("/dev/full"), std::string::npos) << name << ": " << message;
        EXPECT_TRUE(std::filesystem::is_character_file("/dev/full")) << name;
    }
}

TEST(SaveFiles, FailedSaveLeavesTheOldFileWholeAndNothingBeside) {
    const test::ScratchDir dir("save_limit");
    const auto target = dir / "tree.bvh";
    std::ofstream(target) << "the old file";
    for (const auto& [name, save_to] : savers()) {
        std::string message;
        {
            const FileSizeLimit limit(1000);  // each file here is several kB
            ASSERT_TRUE(limit.ok());
            message = save_error_of([&] { save_to(target); });
        }
        EXPECT_NE(message.find(target.string()), std::string::npos) << name << ": " << message;
        EXPECT_EQ(file_text(target), "the old file") << name;
        EXPECT_EQ(dir.names(), std::vector<std::string>{"tree.bvh"}) << name;
    }
}

TEST(SaveFiles, SpecialTargetIsWrittenInPlaceAndLinksAreFollowed) {
    const TriangleBvh<float> tree(make_procedural("sphere:subdiv=2"));
    save(tree, "/dev/null");
    EXPECT_TRUE(std::filesystem::is_character_file("/dev/null"));

    const test::ScratchDir dir("save_link");
    std::ofstream(dir / "real.bvh") << "old";
    std::filesystem::create_symlink("real.bvh", dir / "link.bvh");
    save(tree, dir / "link.bvh");
    EXPECT_TRUE(std::filesystem::is_symlink(dir / "link.bvh"));
    EXPECT_EQ(to_bytes(load_triangle_bvh<float>(dir / "real.bvh")), to_bytes(tree));
    EXPECT_EQ(dir.names(), (std::vector<std::string>{"link.bvh", "real.bvh"}));
}

TEST(LoadFiles, DevZeroFifoAndMissingFiles) {
    const std::string zero = save_error_of([] { load_triangle_bvh<float>("/dev/zero"); });
    EXPECT_NE(zero.find("not a regular file"), std::string::npos) << zero;

    const test::ScratchDir dir("load_special");
    EXPECT_THROW(load_closest_point_mesh<float>(dir / "missing.bvh"), FileNotFoundError);
    const auto fifo = dir / "tree.bvh";
    ASSERT_TRUE(test::make_fifo(fifo));
    std::exception_ptr thrown;
    EXPECT_TRUE(test::returns_without_blocking([&] { load_collision_model<Obb<float>>(fifo); },
                                               fifo, thrown))
        << "the loader blocked on a FIFO";
    EXPECT_TRUE(thrown);
}
