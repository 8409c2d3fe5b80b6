// The one door through which skybake opens the files it reads: every input a
// key or an option names (star catalogue, cloud masks, weather and ground
// maps) and every file a manifest names in a bake's folder.
//
// What the door guarantees, whoever asks:
//  - The file is opened non-blocking (a FIFO does not hang the open) and
//    checked with fstat to be a regular file: a directory, FIFO, socket or
//    device (/dev/zero) is refused with what it is, before any byte is read.
//  - Where no link is expected (a name a manifest lists in its folder) the
//    last component is opened with O_NOFOLLOW, relative to the folder: a
//    link planted at the name is refused, not followed.
//  - At most `max_bytes` are read, whatever the size fstat reports (a file in
//    /proc reports 0), so a huge or growing file is refused, not slurped.
//  - A kept read (ReadKept) reads each path once and returns the same bytes
//    for every later read: one bake sees one input, even if the file changes
//    on disk between its frames. "Once" is once per process, or, where
//    KeptReadScopes are used (the Python module: one per call), once per
//    run of overlapping scopes: a bake after the last one ended reads the
//    files as they are then.
//
// Each function returns "" or the problem as a phrase that completes
// "PATH: ..." ("is a FIFO, a socket or a device, not a regular file"); the
// caller adds the place (the key, the manifest) and the fix, and chooses the
// exit code. Private to skybake's layers; no exceptions.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

namespace skybake {

// Whether the last component of a path may be a symbolic link: yes for a
// path a user gives (a catalogue installed as a link), no for a name in a
// bake's folder.
enum class FileLinks { kFollow, kRefuse };

// Opens `path` for reading as a regular file (see above); on success `fd` is
// a blocking descriptor the caller closes, and "" is returned.
std::string OpenRegularFile(const std::string& path, FileLinks links, int& fd);

// Reads all of `path` (a regular file of at most `max_bytes`) into `bytes`.
std::string ReadRegularFile(const std::string& path, uint64_t max_bytes, FileLinks links, std::string& bytes);

// ReadRegularFile, links followed, once per path (see above): the first
// read's bytes (or its problem) are kept and returned for every later one.
std::string ReadKept(const std::string& path, uint64_t max_bytes, std::shared_ptr<const std::string>& bytes);

// The kept reads of one bake (or check, or style load) in a process that
// runs many: the first scope to open while none is open forgets every kept
// read; scopes open at the same time (bakes on two threads) share theirs.
class KeptReadScope {
 public:
  KeptReadScope();
  ~KeptReadScope();
  KeptReadScope(const KeptReadScope&) = delete;
  KeptReadScope& operator=(const KeptReadScope&) = delete;
};

// Why `name`, read from a manifest (or any file of the folder), cannot be the
// name of a file directly inside that folder: "" when it can. Refuses the
// empty name, "." and "..", a name with '/' or '\', a control character
// (escape sequences reach a terminal), or longer than 255 bytes. The one
// check of every command that opens a name a manifest lists (view, gallery,
// merge-manifest, --resume).
std::string FolderNameProblem(const std::string& name);

// Reads `name` in the folder `dir`: FolderNameProblem, then opened relative
// to `dir` with O_NOFOLLOW, a regular file of at most `max_bytes`.
std::string ReadFolderFile(const std::string& dir, const std::string& name, uint64_t max_bytes, std::string& bytes);

// The output folder held open for a whole bake: OutputLock::Claim
// (output_lock.h) opens the folder once (a descriptor of the directory
// itself, not of its name) and holds it with the lock to the end; every
// output written into it (WriteFileAtomically, exr_io.h) is created and
// renamed relative to that descriptor (openat with O_EXCL | O_NOFOLLOW,
// renameat), and every file of it read here is opened relative to it. A
// folder renamed away and replaced by a link while a sequence runs
// therefore does not redirect its later frames: they land in the folder the
// bake locked.
// Registers `fd`, a directory descriptor of `dir`, until the matching
// ReleaseFolder; a second hold of the same folder shares the first
// descriptor (and closes `fd`). Folders are matched by their path text made
// lexically normal ("out/" and "out" are one).
void HoldFolder(const std::string& dir, int fd);
void ReleaseFolder(const std::string& dir);

// The held descriptor of `dir`, or -1 when the folder is not held.
int HeldFolder(const std::string& dir);

// The size of `path`, a regular file (links refused, held folders
// honoured); "" or the problem.
std::string RegularFileSize(const std::string& path, uint64_t& size);
// RegularFileSize of a file skybake has just written; throws OutputError
// naming it when it is gone or not a regular file (the one exception here).
uint64_t WrittenFileSize(const std::string& path);

// Opens `path` for writing a stream of lines as it happens (--progress-json):
// a regular file (created or emptied), or where a reader already waits a
// pipe or a character device (/dev/fd/N of a wrapper's pipe, /dev/null, a
// terminal). Opened non-blocking, so that a FIFO with no reader is refused at
// once ("is a FIFO (named pipe) that no process reads") instead of hanging;
// a directory, a socket or a block device is refused. On success `fd` is a
// blocking descriptor the caller closes, and "" is returned.
std::string OpenStreamOutput(const std::string& path, int& fd);

// The caps of inputs that have no size of their own: a star catalogue (the
// largest d3-celestial file, stars.14.json, is about 16 MiB) and an image
// file (a 16384 x 16384 RGBA float EXR is 4 GiB uncompressed; a weather map
// or mask of skybake's at most 4096 x 4096 RGBA, as float 256 MiB).
inline constexpr uint64_t kMaxCatalogueBytes = uint64_t(64) << 20;
inline constexpr uint64_t kMaxImageFileBytes = uint64_t(256) << 20;
// The cap of an image's samples (width x height x channels), checked from its
// header before its pixels are decoded: 4096 x 4096 x 4 = 2^26 (256 MiB as
// floats). An 8000 x 8000 PNG of zeros is a small file and is refused here.
inline constexpr uint64_t kMaxImageSamples = uint64_t(1) << 26;

// An image a key names (a cloud mask, a weather map): its file read kept
// (ReadKept, at most kMaxImageFileBytes), its header checked against
// kMaxImageSamples before decoding, its pixels as floats, channels
// interleaved (the OpenImageIO module, oiio_module.h). "" or the problem;
// throws OutputError when the module cannot be loaded.
std::string ReadImageFile(const std::string& path, int& width, int& height, int& channels, std::vector<float>& pixels);

}  // namespace skybake
