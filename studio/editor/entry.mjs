// What the studio's page uses of CodeMirror 6: build.mjs bundles exactly
// these into one ES module, host-sim/src/studio/assets/codemirror.js, which
// editor.js imports (the page loads nothing from the network).

export { EditorState, Transaction } from '@codemirror/state';
export {
  EditorView, drawSelection, highlightActiveLine, highlightActiveLineGutter, highlightSpecialChars, keymap,
  lineNumbers,
} from '@codemirror/view';
export { defaultKeymap, history, historyKeymap, isolateHistory, redo, undo } from '@codemirror/commands';
export { StreamLanguage, syntaxHighlighting } from '@codemirror/language';
export { lintGutter, setDiagnostics } from '@codemirror/lint';
export { highlightSelectionMatches, search, searchKeymap } from '@codemirror/search';
export { classHighlighter } from '@lezer/highlight';
