#pragma once
// The outputs of one run (docs/formats.md, "Outputs"). Every command writes its files through one
// RunFiles object:
// - an output that is the same file as an input or as another output (device and inode, through
//   symbolic links; the same final path when it does not exist yet) is refused before anything is
//   written;
// - a regular file (or a path that does not exist yet) is written to a unique temporary file in the
//   same folder and replaces the target only in commit(), after fsync: a run that fails leaves every
//   pre-existing output byte-identical. A symbolic link is written through to its target;
// - `-` (standard output) and the null device (/dev/null) are written straight and never replaced;
//   a FIFO, a socket or any other device is refused before anything is opened (a FIFO would block
//   until a reader comes: pipe standard output instead);
// - an existing file without write permission is refused, never replaced around its protection
//   (for root, whom the kernel lets write anything: a file with no write bit at all);
// - the temporary files are removed on SIGINT, SIGTERM and SIGHUP (where the command left the signal
//   at its default action): the signal then ends the process as it would have;
// - a write error, EPIPE included, is an Error naming the path; nothing raises a signal (the
//   command line ignores SIGPIPE).

#include <sys/types.h>

#include <initializer_list>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "tetra/core/result.hpp"

namespace tetra {

//! Device and inode of an existing file, through symbolic links.
struct FileId {
  dev_t device = 0;
  ino_t inode = 0;
  bool operator==(const FileId&) const = default;
};
//! The identity of `path`, or nullopt when it does not exist.
std::optional<FileId> file_id(const std::string& path);

//! One output file of a run; made by RunFiles::add.
class OutputFile {
 public:
  OutputFile(const OutputFile&) = delete;
  OutputFile& operator=(const OutputFile&) = delete;
  ~OutputFile();

  //! The path as the user gave it (for messages).
  const std::string& path() const { return path_; }
  //! True for standard output and /dev/null (written straight, never replaced).
  bool is_stream() const { return stream_; }
  //! Appends `data`; an Error names the path (a full disk, a closed pipe). Called as often as
  //! needed: a streaming output writes as it goes into the temporary file, committed at the end.
  Status write(std::string_view data);
  //! The temporary file, for a library that writes the file by name itself (HDF5): it writes there
  //! (and closes the file) before RunFiles::commit(), which fsyncs and renames it as any output.
  //! Bad input naming the option for standard output or /dev/null (such a library seeks).
  Result<std::string> library_path() const;

 private:
  friend class RunFiles;
  OutputFile() = default;
  Status sync();  // fsync and close the temporary file (regular outputs)
  Status rename_into_place();
  void discard();         // removes an uncommitted temporary file
  Status write_behind();  // a long regular output: written to the disk and dropped from the cache as it grows

  std::string path_;    // as given
  std::string label_;   // the option that named it ("--attitude"), for messages
  std::string target_;  // final path, symbolic links resolved
  std::string temp_;    // temporary file next to target_ (regular outputs)
  int fd_ = -1;
  off_t written_bytes_ = 0;  // appended by write()
  off_t queued_bytes_ = 0;   // handed to the disk by write_behind()
  bool stream_ = false;
  bool write_behind_ = true;  // cleared where the file system does not support it
  bool committed_ = false;
  int temp_slot_ = -1;  // the temporary file's entry in the table the signal handler removes
};

//! A text output written as it is produced (replay's attitude and events): appends to a buffer that
//! goes out to the OutputFile (its temporary file) once it holds about 1 MB, so memory is bounded
//! whatever the output's length; the run's RunFiles::commit() renames it into place.
class BufferedOutput {
 public:
  explicit BufferedOutput(OutputFile& out) : out_(out) {}
  //! The buffer to append to; call maybe_flush() after appending.
  std::string& buffer() { return buffer_; }
  //! Writes the buffer out once it holds more than about 1 MB.
  Status maybe_flush() { return buffer_.size() > kFlushBytes ? flush() : ok_status(); }
  //! Writes the buffer out.
  Status flush();

 private:
  static constexpr std::size_t kFlushBytes = std::size_t{1} << 20;
  OutputFile& out_;
  std::string buffer_;
};

//! The checks RunFiles::add makes of an existing file before opening it (regular and writable, or
//! /dev/null), for an output written by other means (appended to, or by another process): bad input
//! naming `label` and `path`. A path that does not exist yet passes.
Status check_output_path(const std::string& path, const std::string& label);

//! The inputs and outputs of one run.
class RunFiles {
 public:
  RunFiles() = default;
  RunFiles(const RunFiles&) = delete;
  RunFiles& operator=(const RunFiles&) = delete;
  ~RunFiles();  // discards every output not committed

  //! Records an input (`label` names it in messages: a path, or the option that gave it). A path that
  //! does not exist is ignored here (its reader reports it).
  void add_input(const std::string& path, const std::string& label);
  //! Opens an output named by option `label` ("--attitude", "-o"). Refused (bad input naming the
  //! option and the path) when it is the same file as an input or another output, a folder, or
  //! cannot be created. `replaces_input` allows exactly one named input to be replaced (an update in
  //! place, e.g. `allan --update-calibration`).
  Result<OutputFile*> add(const std::string& path, const std::string& label,
                          const std::string& replaces_input = "");
  //! An output option that may be absent: `path` empty leaves `*slot` null.
  struct OptionalOutput {
    const std::string& path;
    const char* label;
    OutputFile** slot;
  };
  //! add() for each output given; the first refusal is returned.
  Status add_outputs(std::initializer_list<OptionalOutput> outputs);
  //! add() and write() in one step.
  Status put(const std::string& path, const std::string& label, std::string_view content);
  //! fsyncs every regular output, then renames each into place. Call once, when the run succeeded.
  Status commit();
  //! Input and output paths, for provenance metadata.
  std::vector<std::string> input_paths() const;

 private:
  struct Input {
    std::string path;
    std::string label;
    FileId id;
  };
  Status check_distinct(const OutputFile& out, const std::optional<FileId>& id,
                        const std::string& replaces_input) const;
  std::vector<Input> inputs_;
  std::vector<std::string> input_paths_;
  std::vector<std::unique_ptr<OutputFile>> outputs_;
};

}  // namespace tetra
