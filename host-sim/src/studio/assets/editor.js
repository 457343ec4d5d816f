// The scene editor: CodeMirror 6 (codemirror.js, bundled from studio/editor)
// with line numbers, long lines kept whole (scrolled, never wrapped), the
// format's keywords, numbers, names and comments highlighted (the keywords
// are the core's, keywords.js), every error marked at its line and column,
// and one undo history for typing and the tools' edits alike.
//
// It lives in a shadow root of its own: CodeMirror's styles are then
// constructed style sheets, which the page's Content-Security-Policy
// (style-src 'self') lets in, where in the document it would add <style>
// elements, which that policy refuses.

import {
  EditorState, EditorView, StreamLanguage, classHighlighter, defaultKeymap, drawSelection, highlightActiveLine,
  highlightActiveLineGutter, highlightSelectionMatches, highlightSpecialChars, history, historyKeymap,
  isolateHistory, keymap, lineNumbers, lintGutter, redo, search, searchKeymap, setDiagnostics, syntaxHighlighting,
  Transaction, undo,
} from './codemirror.js';
import { ARITY } from './keywords.js';
import { NUMBER } from './model.js';

const KEYWORDS = new Set(Object.keys(ARITY));
/** Upper case for ASCII letters only: the format matches keywords without
 *  regard to ASCII case, and `ſphere` is no SPHERE. */
const asciiUpper = (word) => word.replace(/[a-z]/g, (c) => c.toUpperCase());

// The scene format's tokens, as the core's lexer reads them: comments from
// `/*` to `*/` across lines and from `//` to the line's end, quoted names,
// and runs of other characters (a keyword, a number, or anything else).
const sceneFormat = StreamLanguage.define({
  name: 'octrace-scene',
  startState: () => ({ inside: null }),
  copyState: (state) => ({ inside: state.inside }),
  token(stream, state) {
    if (state.inside === 'comment') {
      if (stream.skipTo('*/')) { stream.pos += 2; state.inside = null; } else stream.skipToEnd();
      return 'comment';
    }
    if (state.inside === 'name') {
      if (stream.skipTo('"')) { stream.next(); state.inside = null; } else stream.skipToEnd();
      return 'string';
    }
    if (stream.eatSpace()) return null;
    if (stream.match('//')) { stream.skipToEnd(); return 'comment'; }
    if (stream.match('/*')) { state.inside = 'comment'; return 'comment'; }
    if (stream.eat('"')) { state.inside = 'name'; return 'string'; }
    const start = stream.pos;
    while (!stream.eol() && !/\s/.test(stream.peek()) && !stream.match(/^\/[*/]/, false)) stream.next();
    const word = stream.string.slice(start, stream.pos);
    if (KEYWORDS.has(asciiUpper(word))) return 'keyword';
    return NUMBER.test(word) ? 'number' : null;
  },
  languageData: { commentTokens: { line: '//', block: { open: '/*', close: '*/' } } },
});

const theme = EditorView.theme({
  '&': { height: '560px', backgroundColor: '#111', color: '#e8e8e8', fontSize: '12px' },
  '.cm-scroller': { fontFamily: 'ui-monospace, monospace', lineHeight: '1.45' },
  '.cm-gutters': { backgroundColor: '#181a1f', color: '#6b717d', borderRight: '1px solid #2a2d34' },
  '.cm-activeLine': { backgroundColor: '#1b1e24' },
  '.cm-activeLineGutter': { backgroundColor: '#22262e', color: '#b0bec5' },
  '&.cm-focused .cm-cursor': { borderLeftColor: '#ffd54f' },
  '&.cm-focused .cm-selectionBackground, .cm-selectionBackground': { backgroundColor: '#34495e' },
  '.tok-keyword': { color: '#82aaff', fontWeight: 'bold' },
  '.tok-number': { color: '#f5b971' },
  '.tok-string': { color: '#a5d6a7' },
  '.tok-comment': { color: '#7a8499', fontStyle: 'italic' },
  '.cm-panels': { backgroundColor: '#2a2d34', color: '#ddd' },
  '.cm-tooltip': { backgroundColor: '#2a2d34', color: '#ddd', border: '1px solid #555' },
}, { dark: true });

/** `text`'s line breaks, if all are CRLF: the editor keeps them so (and
 *  saves them so); otherwise it splits on any and writes LF. */
const lineBreaksOf = (text) => (/\r\n/.test(text) && !/\r(?!\n)|(?<!\r)\n/.test(text) ? '\r\n' : undefined);

/** The editor, in element `host`. `onChange()` is called after every change
 *  of the text (typing, a tool's edit, undo) but a drag's previews. */
export function createEditor(host, onChange) {
  const root = host.attachShadow({ mode: 'open' });
  const extensions = (separator) => [
    lineNumbers(), highlightActiveLineGutter(), highlightSpecialChars(), history(), drawSelection(),
    highlightActiveLine(), highlightSelectionMatches(), search({ top: true }), lintGutter(), sceneFormat,
    syntaxHighlighting(classHighlighter), theme, keymap.of([...defaultKeymap, ...historyKeymap, ...searchKeymap]),
    EditorView.contentAttributes.of({ 'aria-label': 'scene text', spellcheck: 'false' }),
    EditorView.updateListener.of((update) => {
      if (update.docChanged && !update.transactions.some((t) => t.isUserEvent('preview'))) onChange();
    }),
    ...(separator ? [EditorState.lineSeparator.of(separator)] : []),
  ];
  const view = new EditorView({ parent: root, state: EditorState.create({ extensions: extensions() }) });
  // Whether errors are marked (none to mark and none marked: nothing to do,
  // as for every frame played of a scene without errors).
  let marked = false;

  const text = () => view.state.doc.toString();

  /** The change from the text to `value`: the span between what they
   *  share at the start and at the end. */
  function change(value) {
    const now = text();
    let from = 0;
    while (from < now.length && from < value.length && now[from] === value[from]) from++;
    let end = 0;
    while (end < now.length - from && end < value.length - from && now[now.length - 1 - end] === value[value.length - 1 - end]) end++;
    return { from, to: now.length - end, insert: value.slice(from, value.length - end) };
  }

  /** The offset of `line` and `column` (the core's: from 1, in characters,
   *  not UTF-16 units), kept within the text. */
  function offsetOf(line, column) {
    const doc = view.state.doc;
    const at = doc.line(Math.max(1, Math.min(line, doc.lines)));
    let offset = at.from;
    for (const character of at.text) {
      if (column <= 1) break;
      offset += character.length;
      column -= 1;
    }
    return offset;
  }

  return {
    view,
    text,
    /** A scene loaded: the text, a new history. */
    load(value) {
      view.setState(EditorState.create({ doc: value, extensions: extensions(lineBreaksOf(value)) }));
      marked = false;
      onChange();
    },
    /** The text becomes `value` as one step of the history (a tool's
     *  edit), or, with `preview`, outside it and without `onChange` (a
     *  drag under way; `commit` ends it). */
    edit(value, preview = false) {
      if (value === text()) return;
      view.dispatch({
        changes: change(value),
        userEvent: preview ? 'preview.drag' : 'input.tool',
        annotations: preview ? Transaction.addToHistory.of(false) : isolateHistory.of('full'),
      });
    },
    /** A drag that began at `base` ends at `value`: one step of the history. */
    commit(base, value) {
      this.edit(base, true);
      this.edit(value);
    },
    /** Marks `errors` ({line, column, message, board}) in the text: each
     *  from its column to the end of the word there (a point at a space or
     *  the end); line 0 is the whole scene's, not marked. */
    setErrors(errors) {
      if (!errors.length && !marked) return;
      marked = errors.length > 0;
      const doc = view.state.doc;
      const diagnostics = errors.filter((e) => e.line > 0).map((e) => {
        const from = offsetOf(e.line, e.column);
        const word = /^[^\s]*/.exec(doc.sliceString(from, doc.lineAt(from).to))[0];
        return { from, to: from + word.length, severity: 'error', message: e.message, source: e.board ? 'board' : undefined };
      });
      view.dispatch(setDiagnostics(view.state, diagnostics));
    },
    /** Puts the cursor at `line`, `column` (the core's) and the focus in the editor. */
    goTo(line, column) {
      const at = offsetOf(line, column);
      view.dispatch({ selection: { anchor: at }, scrollIntoView: true });
      view.focus();
    },
    undo: () => undo(view),
    redo: () => redo(view),
  };
}
