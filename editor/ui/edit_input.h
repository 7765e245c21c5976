#pragma once
// Connects the editor window's interactor to EditWindow: the interaction style (painting,
// editor keys, slice scrolling, VTK's camera otherwise), the autosave timer's callback and
// the window manager's close button.
namespace sslpv {

class EditWindow;

/// Call once after constructing the window, before Initialize()/Start().
void attachEditorInput(EditWindow& window);

}  // namespace sslpv
