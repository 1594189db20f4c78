#pragma once
// Output files that appear together or not at all: a face's OBJ, material
// and texture; the seven wrinkle maps and their layouts; an animation's
// frames; or one picture or video. write_file_atomically (atomic_file.h)
// does this for one file; a batch does it for many:
//
//   OutputBatch out("frames", "play: --out frames/%04d.png");  // checked now
//   ... load, render ...
//   write_image(out.stage("f_0000.png"), image);   // into a staging folder
//   ...
//   out.commit();   // every staged file moved into frames/
//
// The staging folder is made inside the destination folder when the batch is
// made, which is also the check that the destination can be written at all,
// before any slow work. A batch destroyed without commit() (an exception on
// the way) removes the staging folder and the folders it made, so a failed
// command leaves the destination as it was.
#include <string>
#include <vector>

namespace emoface {

class OutputBatch {
public:
    // `folder`: where the files go ("" is the current folder), made with its
    // missing parents. `what`: the user's words for messages, e.g.
    // "play: --out frames/%04d.png". Throws InputError
    //   "<what>: <folder> is a file, not a folder" or
    //   "<what>: cannot write there: <the system's reason>".
    OutputBatch(const std::string& folder, std::string what);
    ~OutputBatch();
    OutputBatch(const OutputBatch&) = delete;
    OutputBatch& operator=(const OutputBatch&) = delete;

    // The path to write the file that will become folder/name (a plain file
    // name: the extension is kept, as image and video libraries choose the
    // format by it). A staged name the writer never wrote is skipped by
    // commit() (a video writer that fell back to another container).
    std::string stage(const std::string& name);
    // folder/name: where a staged file ends up.
    std::string destination(const std::string& name) const;
    const std::string& folder() const { return folder_; }

    // Moves every staged file into place, replacing files of the same name.
    // A destination that is a folder, or a move that fails, throws InputError
    // "<what>: cannot write <destination>: <reason>" after putting back what
    // the earlier moves replaced: all or nothing.
    void commit();

    // The user's name for a path written into a staging folder (the
    // staging folder left out), `path` itself otherwise: writers name this
    // in their messages, never the hidden folder.
    static std::string shown_path(const std::string& path);

private:
    void discard() noexcept;

    std::string folder_, what_;
    std::string staging_;           // folder/.emoface-<pid>-<n>.tmp
    std::vector<std::string> made_;  // folders this batch made, deepest first
    std::vector<std::string> names_;
    bool committed_ = false;
};

}  // namespace emoface
